#pragma once
// Eigen's dense symmetric eigen-decomposition and Cholesky factorisation of MatrixXd are
// compiled once, in model/src/dynamics/eigen_instances.cpp, instead of in every
// translation unit that uses them (rom.cpp, full_model.cpp, newmark.cpp and the dynamics
// tests). Their instantiation (tridiagonalisation, the implicit QR sweeps, the blocked
// Cholesky) cost ~6 s of compile time per TU natively and ~17 s under ASan+UBSan
// (docs/ci.md). Only the calls whose argument is a plain MatrixXd use these: evaluate an
// expression into a MatrixXd first (the decomposition reads the evaluated matrix either
// way, so the numbers are the same). Model building only: the real-time ROM step uses
// neither.
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

extern template Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>&
Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>::compute(const Eigen::EigenBase<Eigen::MatrixXd>&,
                                                        int);
extern template Eigen::LLT<Eigen::MatrixXd>& Eigen::LLT<Eigen::MatrixXd>::compute(
    const Eigen::EigenBase<Eigen::MatrixXd>&);
