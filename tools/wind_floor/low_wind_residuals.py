#!/usr/bin/env python3
"""Where the wind load model's error at low wind comes from (docs/wind.md, "Kelmarsh").

Reads the per-row output of `drivetwin torque --compare --json` and the Kelmarsh SCADA
file it was run on (joined by row number), and prints the MAPE and mean signed error of
the rows in operation with a nacelle wind in [3, 5) m/s, split by measured blade pitch,
rotor speed, ambient temperature and yaw error, for the calendar months given.

Usage:
  drivetwin torque K.csv --columns kelmarsh --drivetrain kelmarsh-mm92 --compare --json > rows.json
  python3 tools/wind_floor/low_wind_residuals.py K.csv rows.json [first_month last_month]
Host tool, standard library only (Debian's python3).
"""
import csv
import json
import sys


def load_scada(path):
    rows = []
    with open(path, encoding="utf-8") as f:
        reader = csv.reader(f)
        header = next(reader)
        col = {name: i for i, name in enumerate(header)}

        def value(x, name):
            try:
                return float(x[col[name]])
            except (ValueError, IndexError):
                return None

        for x in reader:
            rows.append({
                "month": int(x[col["Date and time"]][5:7]),
                "pitch": value(x, "Pitch angle (°)"),
                "rpm": value(x, "Rotor speed (RPM)"),
                "temperature": value(x, "Nacelle ambient temperature (°C)"),
                "yaw": value(x, "Yaw error (°)"),
            })
    return rows


def line(label, errors):
    if not errors:
        return
    mape = sum(abs(e) for e in errors) / len(errors)
    bias = sum(errors) / len(errors)
    print(f"| {label} | {len(errors)} | {mape:.2f} | {bias:+.2f} |")


def main():
    scada = load_scada(sys.argv[1])
    months = (int(sys.argv[3]), int(sys.argv[4])) if len(sys.argv) > 4 else (1, 12)
    with open(sys.argv[2], encoding="utf-8") as f:
        estimates = json.load(f)["rows"]
    low = []
    for e in estimates:
        if not e.get("in_operation"):
            continue
        if not 3.0 <= e["wind_speed_mps"] < 5.0:
            continue
        s = scada[e["row"] - 1]
        if not months[0] <= s["month"] <= months[1]:
            continue
        s = dict(s)
        s["error"] = 100.0 * (e["estimate_nm"] - e["reference_nm"]) / e["reference_nm"]
        low.append(s)
    print(f"rows in operation at 3-5 m/s, months {months[0]}-{months[1]}")
    print("| group | rows | MAPE % | bias % |\n|---|---|---|---|")
    line("all", [r["error"] for r in low])
    splits = (
        ("pitch (deg)", "pitch", (-90, 0.01, 0.5, 1.0, 90)),
        ("rotor speed (rpm)", "rpm", (0, 8.3, 8.7, 9.5, 30)),
        ("temperature (degC)", "temperature", (-60, 5, 10, 15, 20, 60)),
        ("yaw error (deg)", "yaw", (-180, -15, -5, 5, 15, 180)),
    )
    for name, key, edges in splits:
        for lo, hi in zip(edges[:-1], edges[1:]):
            errors = [r["error"] for r in low if r[key] is not None and lo <= r[key] < hi]
            line(f"{name} {lo} to {hi}", errors)


if __name__ == "__main__":
    main()
