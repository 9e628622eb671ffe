#!/usr/bin/env python3
"""The statistics `drivetwin synth-scada` draws its 10-minute winds from (app/wind/synthetic_wind.hpp).

fit:     fits them to a site's 10-minute SCADA (Kelmarsh columns: "Date and time", "Wind speed
         (m/s)"): the annual and the diurnal cycle of the mean wind as first harmonics,
         the Weibull shape and scale of the wind with both cycles divided out (method of
         moments), and the two-scale persistence of the Gaussianised residual (lag 1 exact,
         least squares at lags 2 rows to 3 days, inside gap-free blocks).
measure: the same statistics of a file (Kelmarsh or synth-scada columns) without fitting,
         to compare a synthetic history against the site: mean and standard deviation,
         monthly means, the diurnal cycle, the within-day wander (mean over full days of the
         standard deviation of the day's 10-minute means) and the lag correlations of the
         Gaussianised wind.

Usage:
  python3 tools/wind_floor/fit_synthetic_wind.py fit     ../shared/data/kelmarsh/kelmarsh-t1-2019.csv
  python3 tools/wind_floor/fit_synthetic_wind.py measure /tmp/scada-11y.csv
Host tool, standard library only (Debian's python3).
"""
import csv
import datetime as dt
import math
import statistics as st
import sys
from collections import defaultdict

PERIOD_S = 600.0
YEAR_DAYS = 365.25
LAGS = [1, 2, 3, 6, 12, 24, 36, 72, 144, 288, 432]  # rows of 10 minutes: 10 min to 3 days


def load(path):
    """[(unix seconds, wind m/s)] of the finite rows, in time order."""
    rows = []
    with open(path, encoding="utf-8") as f:
        reader = csv.reader(f)
        header = next(reader)
        col = {name: i for i, name in enumerate(header)}
        if "t_s" in col:
            tcol, vcol, kelmarsh = col["t_s"], col["wind_speed_mps"], False
        else:
            tcol, vcol, kelmarsh = col["Date and time"], col["Wind speed (m/s)"], True
        for x in reader:
            try:
                v = float(x[vcol])
                if kelmarsh:
                    t = dt.datetime.strptime(x[tcol], "%Y-%m-%d %H:%M:%S").replace(
                        tzinfo=dt.timezone.utc).timestamp()
                else:
                    t = float(x[tcol])
            except (ValueError, IndexError):
                continue
            if math.isfinite(v) and v >= 0.0:
                rows.append((t, v))
    rows.sort()
    return rows


def day_of_year(t):
    return (t / 86400.0) % YEAR_DAYS  # days since 1 January (4-year mean calendar)


def hour_of_day(t):
    return (t % 86400.0) / 3600.0


def harmonic(points, period):
    """Least-squares y = m·(1 + a·cos(2π(x − x0)/period)) through (x, y): (m, a, x0)."""
    n = len(points)
    m = sum(y for _, y in points) / n
    c = sum(y * math.cos(2 * math.pi * x / period) for x, y in points) * 2 / n
    s = sum(y * math.sin(2 * math.pi * x / period) for x, y in points) * 2 / n
    return m, math.hypot(c, s) / m, (math.atan2(s, c) * period / (2 * math.pi)) % period


def cycle_factor(t, p):
    return (1 + p["seasonal_amplitude"] * math.cos(
        2 * math.pi * (day_of_year(t) - p["seasonal_peak_day"]) / YEAR_DAYS)) * (
            1 + p["diurnal_amplitude"] * math.cos(
                2 * math.pi * (hour_of_day(t) - p["diurnal_peak_hour"]) / 24.0))


def phi_inv(u):
    """Standard normal quantile (Acklam's rational approximation, refined by one Halley step)."""
    u = min(max(u, 1e-12), 1 - 1e-12)
    a = [-3.969683028665376e+01, 2.209460984245205e+02, -2.759285104469687e+02,
         1.383577518672690e+02, -3.066479806614716e+01, 2.506628277459239e+00]
    b = [-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
         6.680131188771972e+01, -1.328068155288572e+01]
    c = [-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
         -2.549732539343734e+00, 4.374664141464968e+00, 2.938163982698783e+00]
    d = [7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
         3.754408661907416e+00]
    if u < 0.02425:
        q = math.sqrt(-2 * math.log(u))
        x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) / \
            ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1)
    elif u > 1 - 0.02425:
        q = math.sqrt(-2 * math.log(1 - u))
        x = -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) / \
            ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1)
    else:
        q = u - 0.5
        r = q * q
        x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q / \
            (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1)
    e = 0.5 * math.erfc(-x / math.sqrt(2)) - u
    w = e * math.sqrt(2 * math.pi) * math.exp(x * x / 2)
    return x - w / (1 + x * w / 2)


def weibull_moments(values):
    """Weibull (k, c) with the sample's mean and standard deviation (bisection on k)."""
    mean, sd = st.fmean(values), st.pstdev(values)
    lo, hi = 0.5, 10.0
    for _ in range(100):
        k = 0.5 * (lo + hi)
        g1, g2 = math.gamma(1 + 1 / k), math.gamma(1 + 2 / k)
        cv = math.sqrt(g2 - g1 * g1) / g1
        lo, hi = (k, hi) if cv > sd / mean else (lo, k)
    return k, mean / math.gamma(1 + 1 / k)


def lag_correlations(t, z):
    """corr(z_i, z_{i+L}) over pairs exactly L rows apart in time (gaps excluded)."""
    index = {round(ti / PERIOD_S): i for i, ti in enumerate(t)}
    out = {}
    for lag in LAGS:
        pairs = [(z[i], z[index[k + lag]]) for k, i in index.items() if k + lag in index]
        if len(pairs) < 30:
            continue
        xs, ys = [p[0] for p in pairs], [p[1] for p in pairs]
        out[lag] = (st.correlation(xs, ys), len(pairs))
    return out


def model_corr(w, tau_rows, phi_f, lag):
    return w * math.exp(-lag / tau_rows) + (1 - w) * phi_f ** lag


def fit_persistence(corr):
    """Two-scale AR(1) (w, τ_s rows, φ_f) with lag 1 matched, least squares elsewhere."""
    r1 = corr[1][0]
    best = None
    for i in range(1, 400):
        tau = 2.0 + i * 0.5  # rows
        for j in range(0, 96):
            phi_f = j * 0.01
            ps = math.exp(-1 / tau)
            if ps <= phi_f:
                continue
            w = (r1 - phi_f) / (ps - phi_f)  # lag 1 exact
            if not 0 < w <= 1:
                continue
            err = sum((model_corr(w, tau, phi_f, lag) - c) ** 2 for lag, (c, _) in corr.items())
            if best is None or err < best[0]:
                best = (err, w, tau, phi_f)
    return best[1:]


def wander(t, v):
    by_day = defaultdict(list)
    for ti, vi in zip(t, v):
        by_day[int(ti // 86400)].append(vi)
    days = [st.pstdev(d) for d in by_day.values() if len(d) >= 140]
    return (st.fmean(days) if days else float("nan")), len(days)


def describe(t, v, z):
    print(f"rows {len(v)}: mean {st.fmean(v):.2f} m/s, sd {st.pstdev(v):.2f} m/s")
    months = defaultdict(list)
    for ti, vi in zip(t, v):
        months[dt.datetime.fromtimestamp(ti, dt.timezone.utc).month].append(vi)
    print("monthly mean [m/s]: " + " ".join(
        f"{m}:{st.fmean(months[m]):.2f}" for m in sorted(months)))
    hours = defaultdict(list)
    for ti, vi in zip(t, v):
        hours[int(hour_of_day(ti))].append(vi)
    mean = st.fmean(v)
    print("hour-of-day mean / mean: " + " ".join(
        f"{st.fmean(hours[h]) / mean:.3f}" for h in sorted(hours)))
    w, n = wander(t, v)
    print(f"within-day wander (sd of a full day's 10-min means, mean over {n} days): {w:.2f} m/s")
    corr = lag_correlations(t, z)
    print("lag [rows] / corr of z (pairs): " + " ".join(
        f"{lag}:{c:.3f}({n})" for lag, (c, n) in corr.items()))
    return corr


def main():
    if len(sys.argv) != 3 or sys.argv[1] not in ("fit", "measure"):
        sys.exit(__doc__)
    rows = load(sys.argv[2])
    if len(rows) < 1000:
        sys.exit(f"{sys.argv[2]}: {len(rows)} usable rows, too few to fit")
    t = [r[0] for r in rows]
    v = [r[1] for r in rows]
    if sys.argv[1] == "measure":
        k, c = weibull_moments(v)
        z = [phi_inv(1 - math.exp(-(vi / c) ** k)) for vi in v]
        describe(t, v, z)
        return
    # The annual cycle from the monthly means at each month's mid-day (each month weighs the
    # same however many rows it has); the diurnal cycle from the hour-of-day means of the wind
    # divided by its month's mean (so the sampled days' weather does not enter it).
    months = defaultdict(list)
    for ti, vi in zip(t, v):
        months[dt.datetime.fromtimestamp(ti, dt.timezone.utc).month].append((ti, vi))
    monthly = [(st.fmean(day_of_year(ti) for ti, _ in rs), st.fmean(vi for _, vi in rs))
               for rs in months.values()]
    _, a_s, d_s = harmonic(monthly, YEAR_DAYS)
    month_mean = {m: st.fmean(vi for _, vi in rs) for m, rs in months.items()}
    hours = defaultdict(list)
    for ti, vi in zip(t, v):
        m = dt.datetime.fromtimestamp(ti, dt.timezone.utc).month
        hours[int(hour_of_day(ti))].append(vi / month_mean[m])
    hourly = [(h + 0.5, st.fmean(x)) for h, x in hours.items()]
    _, a_d, h_d = harmonic(hourly, 24.0)
    p = {"seasonal_amplitude": a_s, "seasonal_peak_day": d_s, "diurnal_amplitude": a_d,
         "diurnal_peak_hour": h_d}
    residual = [vi / cycle_factor(ti, p) for ti, vi in zip(t, v)]
    k, c = weibull_moments(residual)
    z = [phi_inv(1 - math.exp(-(ri / c) ** k)) for ri in residual]
    corr = describe(t, v, z)
    w, tau, phi_f = fit_persistence(corr)
    print(f"fit: weibull_k {k:.3f}, weibull_c {c:.3f} m/s (cycles divided out); "
          f"seasonal_amplitude {a_s:.3f}, seasonal_peak_day {d_s:.1f}; "
          f"diurnal_amplitude {a_d:.3f}, diurnal_peak_hour {h_d:.2f}; "
          f"slow_weight {w:.3f}, slow_time_constant {tau:.1f} rows ({tau * PERIOD_S:.0f} s), "
          f"fast_lag1 {phi_f:.2f}")
    print("model corr: " + " ".join(
        f"{lag}:{model_corr(w, tau, phi_f, lag):.3f}" for lag in corr))


if __name__ == "__main__":
    main()
