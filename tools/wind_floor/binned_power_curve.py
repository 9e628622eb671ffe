#!/usr/bin/env python3
"""Empirical benchmark for the Kelmarsh torque MAPE (README, "Wind load").

A purely empirical estimator with no physics: the measured power binned in wind
speed and rotor speed on January-March 2019, each bin's value the 1/P-weighted
median (the constant that minimises the MAPE within the bin), applied to
April-December 2019 (the seasons are in the test). Rows in operation are selected exactly as app/wind/torque_estimate.hpp
does (wind in [3, 24) m/s, rotor >= 0.9 x 8.14 rpm (kelmarsh-mm92's speed floor), P > 0, pitch <= 3 deg below
12.5 m/s, P >= 50 % rated above). Comparing P is comparing P/omega: the same
measured omega divides both.

Usage: python3 tools/wind_floor/binned_power_curve.py ../shared/data/kelmarsh/kelmarsh-t1-2019.csv
Host tool, standard library only (Debian's python3).
"""
import collections
import csv
import statistics
import sys


def load(path):
    rows = []
    with open(path, encoding="utf-8") as f:
        reader = csv.reader(f)
        header = next(reader)
        col = {name: i for i, name in enumerate(header)}
        for x in reader:
            try:
                rows.append({
                    "t": x[col["Date and time"]],
                    "v": float(x[col["Wind speed (m/s)"]]),
                    "rpm": float(x[col["Rotor speed (RPM)"]]),
                    "pitch": float(x[col["Pitch angle (\u00b0)"]]),
                    "P": float(x[col["Power (kW)"]]),
                })
            except ValueError:
                continue  # an empty cell: the C++ tool does not count such rows either
    return rows


def in_operation(d):
    if not 3.0 <= d["v"] < 24.0 or d["rpm"] < 0.9 * 8.14 or d["P"] <= 0.0:
        return False
    if d["v"] < 12.5 and d["pitch"] > 3.0:
        return False
    return not (d["v"] >= 12.5 and d["P"] < 0.5 * 2050.0)


def weighted_median(values):
    values = sorted(values)
    total = sum(1.0 / p for p in values)
    acc = 0.0
    for p in values:
        acc += 1.0 / p
        if acc >= total / 2.0:
            return p
    return values[-1]


def run(fit, test, dv, drpm):
    bins = collections.defaultdict(list)
    wind_only = collections.defaultdict(list)
    for d in fit:
        bins[(int(d["v"] / dv), int(d["rpm"] / drpm))].append(d["P"])
        wind_only[int(d["v"] / dv)].append(d["P"])
    table = {k: weighted_median(v) for k, v in bins.items() if len(v) >= 3}
    fallback = {k: weighted_median(v) for k, v in wind_only.items()}

    def mape(rows):
        errors = []
        for d in rows:
            key = (int(d["v"] / dv), int(d["rpm"] / drpm))
            p = table.get(key, fallback.get(key[0]))
            if p is None:
                p = fallback[min(fallback, key=lambda k: abs(k - key[0]))]
            errors.append(100.0 * abs(p - d["P"]) / d["P"])
        return statistics.mean(errors), len(errors)

    return mape(fit), mape(test)


def run_keyed(fit, test, key, wind_key):
    """MAPE on `test` of bins by key(d), falling back to bins by wind_key(d) (then the nearest)."""
    bins = collections.defaultdict(list)
    wind_only = collections.defaultdict(list)
    for d in fit:
        bins[key(d)].append(d["P"])
        wind_only[wind_key(d)].append(d["P"])
    table = {k: weighted_median(v) for k, v in bins.items() if len(v) >= 3}
    fallback = {k: weighted_median(v) for k, v in wind_only.items()}
    errors = []
    for d in test:
        p = table.get(key(d), fallback.get(wind_key(d)))
        if p is None:
            p = fallback[min(fallback, key=lambda k: abs(k - wind_key(d)))]
        errors.append(100.0 * abs(p - d["P"]) / d["P"])
    return statistics.mean(errors), len(errors)


def main():
    rows = [d for d in load(sys.argv[1]) if in_operation(d)]
    fit = [d for d in rows if d["t"] < "2019-04-01"]
    test = [d for d in rows if "2019-04-01" <= d["t"] < "2020-01-01"]
    print("bins (wind m/s x rotor rpm)   fitting Jan-Mar   held-out Apr-Dec")
    for dv, drpm in ((0.5, 100.0), (0.25, 100.0), (0.5, 0.5), (0.5, 0.25), (0.25, 0.25)):
        (f, nf), (t, nt) = run(fit, test, dv, drpm)
        label = f"{dv} x {'-' if drpm > 50 else drpm}"
        print(f"{label:29s} {f:6.2f} % ({nf})   {t:6.2f} % ({nt})")
    # The low-wind rows: what the wind, rotor speed and pitch columns carry there.
    low = [d for d in test if 3.0 <= d["v"] < 5.0]
    pitched = [d for d in rows if d["v"] < 5.0 and d["pitch"] >= 1.0]
    print(f"held-out rows at 3-5 m/s: {len(low)}; rows below 5 m/s pitched >= 1 deg: "
          f"{sum(1 for d in pitched if d['t'] < '2019-04-01')} in Jan-Mar, "
          f"{sum(1 for d in pitched if d['t'] >= '2019-04-01')} in Apr-Dec")
    wind_key = lambda d: int(d["v"] / 0.25)
    for label, key in (
            ("3-5 m/s, 0.25 m/s x 0.25 rpm", lambda d: (wind_key(d), int(d["rpm"] / 0.25))),
            ("3-5 m/s, same x 0.5 deg pitch",
             lambda d: (wind_key(d), int(d["rpm"] / 0.25), int(d["pitch"] / 0.5)))):
        t, nt = run_keyed(fit, low, key, wind_key)
        print(f"{label:29s}                   {t:6.2f} % ({nt})")


if __name__ == "__main__":
    main()
