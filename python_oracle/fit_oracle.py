#!/usr/bin/env python3
"""Reference fits for glassdb-fit (test oracle, not used at run time).

Recomputes the constrained least-squares fit of `docs/method.md` eqs. 11-14,

    value(theta) = normal * C(theta),  C(theta) = sum_k c_k cos(theta)^p_k,  C(0 deg) = 1,

in 50-digit arithmetic (mpmath), independently of the Rust code: the constraint eliminates the
lowest-power coefficient (c_p0 = 1 - sum of the others) and the remaining power-basis least
squares is solved by mpmath's Householder QR at mp.dps = 50. Without a 0 deg row the absolute
curve is fitted unconstrained and normal = its value at cos theta = 1 (as glassdb does).

Commands (all print JSON on stdout):

  fit CSV --column R|T --basis full|paper --degree N
      {"normal", "coefficients" (power basis, 1..n or 0..n), "fitted" (normal*C at each row,
       in file order), "angle_deg", "power_condition_number"}
      Numbers are printed as decimal strings with 30 significant digits.

  normal-equations CSV --column R|T --basis full|paper --degree N
      The same fit in float64 by the normal equations (A^T A) c = A^T b solved by Gaussian
      elimination with partial pivoting (numpy.linalg.solve, LAPACK gesv), compared with the
      50-digit reference: digits correct in coefficients and in fitted values, cond(A),
      cond(A^T A).

  digits-table CSV --glassdb PATH [--column R] [--basis full] [--degrees 2 4 ...]
      The markdown table of docs/fit.md: per degree, the digits kept by the normal equations,
      by float64 SVD on the power basis, and by `glassdb fit` (run from PATH).

The CSV is the angle-table format of glassdb (header `angle_deg` plus `R`/`T` columns, rows in
any order); repeated angles are averaged, as glassdb does.
"""

import argparse
import csv
import json
import math
import sys

import mpmath as mp
import numpy as np

mp.mp.dps = 50


def read_curve(path, column):
    with open(path, newline="") as f:
        rows = [r for r in csv.reader(line for line in f if not line.lstrip().startswith("#"))]
    header = [h.strip().lower() for h in rows[0]]
    names = {"r": ("r", "reflectance"), "t": ("t", "transmittance")}[column.lower()]
    ai = next(i for i, h in enumerate(header) if h in ("angle_deg", "theta_deg"))
    vi = next(i for i, h in enumerate(header) if h in names)
    groups = {}
    order = []
    for r in rows[1:]:
        if not r or r[vi].strip() == "":
            continue
        a = mp.mpf(r[ai].strip())
        key = r[ai].strip()
        if a not in groups:
            groups[a] = []
            order.append(a)
        groups[a].append(mp.mpf(r[vi].strip()))
    angles = sorted(groups)
    values = [mp.fsum(groups[a]) / len(groups[a]) for a in angles]
    return angles, values


def cosd(a):
    if a == 90:
        return mp.mpf(0)
    return mp.cos(mp.radians(a))


def powers_of(basis, degree):
    return list(range(1, degree + 1)) if basis == "paper" else list(range(0, degree + 1))


def fit_mp(angles, values, basis, degree):
    """50-digit constrained (or, without a 0 deg row, unconstrained) least squares."""
    powers = powers_of(basis, degree)
    xs = [cosd(a) for a in angles]
    if angles[0] == 0:
        normal = values[0]
        rows = [(x, v / normal) for a, x, v in zip(angles, xs, values) if a != 0]
        p0 = powers[0]
        if len(powers) == 1:
            coef = [mp.mpf(1)]
        else:
            A = mp.matrix(len(rows), len(powers) - 1)
            b = mp.matrix(len(rows), 1)
            for i, (x, z) in enumerate(rows):
                for j, p in enumerate(powers[1:]):
                    A[i, j] = x**p - x**p0
                b[i] = z - x**p0
            sol, _res = mp.qr_solve(A, b)
            rest = [sol[j] for j in range(len(powers) - 1)]
            coef = [1 - mp.fsum(rest)] + rest
    else:
        A = mp.matrix(len(xs), len(powers))
        b = mp.matrix(len(xs), 1)
        for i, (x, v) in enumerate(zip(xs, values)):
            for j, p in enumerate(powers):
                A[i, j] = x**p
            b[i] = v
        sol, _res = mp.qr_solve(A, b)
        absolute = [sol[j] for j in range(len(powers))]
        normal = mp.fsum(absolute)
        coef = [c / normal for c in absolute]
    fitted = [normal * mp.fsum(c * x**p for c, p in zip(coef, powers)) for x in xs]
    return normal, powers, coef, fitted, xs


def power_matrix_f64(xs, powers):
    return np.array([[float(x) ** p for p in powers] for x in xs])


def s30(x):
    return mp.nstr(x, 30, min_fixed=-1, max_fixed=-1) if x != 0 else "0"


def digits(err, ref):
    """Correct significant digits: -log10(max |err| / max |ref|), capped at 17."""
    scale = max(abs(float(r)) for r in ref)
    e = max(abs(x) for x in err)
    if e == 0:
        return 17.0
    return min(17.0, -math.log10(float(e) / scale))


def cmd_fit(args):
    angles, values = read_curve(args.csv, args.column)
    normal, powers, coef, fitted, xs = fit_mp(angles, values, args.basis, args.degree)
    out = {
        "normal": s30(normal),
        "basis": args.basis,
        "powers": powers,
        "coefficients": [s30(c) for c in coef],
        "angle_deg": [s30(a) for a in angles],
        "fitted": [s30(f) for f in fitted],
        "power_condition_number": float(np.linalg.cond(power_matrix_f64(xs, powers))),
    }
    json.dump(out, sys.stdout, indent=1)
    print()


def cmd_normal_equations(args):
    angles, values = read_curve(args.csv, args.column)
    normal, powers, coef, fitted, xs = fit_mp(angles, values, args.basis, args.degree)
    if angles[0] != 0:
        sys.exit("normal-equations needs a 0 deg row (the constrained fit)")
    n0 = float(normal)
    rows = [(float(x), float(v) / n0) for a, x, v in zip(angles, xs, values) if a != 0]
    p0 = powers[0]
    A = np.array([[x**p - x**p0 for p in powers[1:]] for x, _ in rows])
    b = np.array([z - x**p0 for x, z in rows])
    ata = A.T @ A
    atb = A.T @ b
    rest = np.linalg.solve(ata, atb)  # LAPACK gesv: Gaussian elimination, partial pivoting
    c_ne = np.concatenate([[1.0 - rest.sum()], rest])
    xf = np.array([float(x) for x in xs])
    fitted_ne = n0 * sum(c * xf**p for c, p in zip(c_ne, powers))
    # the same system solved by float64 Householder QR on the power basis (numpy lstsq is SVD)
    rest_qr = np.linalg.lstsq(A, b, rcond=None)[0]
    c_qr = np.concatenate([[1.0 - rest_qr.sum()], rest_qr])
    fitted_qr = n0 * sum(c * xf**p for c, p in zip(c_qr, powers))
    out = {
        "degree": args.degree,
        "basis": args.basis,
        "points": len(angles),
        "cond_A": float(np.linalg.cond(A)),
        "cond_AtA": float(np.linalg.cond(ata)),
        "normal_equations": {
            "coefficient_digits": digits([mp.mpf(c) - r for c, r in zip(c_ne, coef)], coef),
            "fitted_digits": digits([mp.mpf(f) - r for f, r in zip(fitted_ne, fitted)], fitted),
        },
        "power_basis_svd_float64": {
            "coefficient_digits": digits([mp.mpf(c) - r for c, r in zip(c_qr, coef)], coef),
            "fitted_digits": digits([mp.mpf(f) - r for f, r in zip(fitted_qr, fitted)], fitted),
        },
    }
    json.dump(out, sys.stdout, indent=1)
    print()


def cmd_digits_table(args):
    """The docs/fit.md table: normal equations vs f64 SVD vs glassdb, digits kept per degree."""
    import subprocess

    print("| degree | cond(A), power basis | cond(AᵀA) | normal eq.: coef. digits | normal eq.: value digits "
          "| f64 SVD, power basis: value digits | glassdb: coef. digits | glassdb: value digits | glassdb cond (solved) |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    quantity = "reflectance" if args.column.lower() == "r" else "transmittance"
    for d in args.degrees:
        args.degree = d
        angles, values = read_curve(args.csv, args.column)
        normal, powers, coef, fitted, xs = fit_mp(angles, values, args.basis, d)
        out = subprocess.run([args.glassdb, "fit", args.csv, "--degree", str(d), "--basis", args.basis, "--json"],
                             check=True, capture_output=True, text=True).stdout
        ours = json.loads(out)["glasses"][0][quantity]
        xf = [float(x) for x in xs]
        of = [ours["normal"] * sum(c * x**p for c, p in zip(ours["coefficients"], ours["powers"])) for x in xf]
        cd = digits([mp.mpf(a) - b for a, b in zip(ours["coefficients"], coef)], coef)
        vd = digits([mp.mpf(a) - b for a, b in zip(of, fitted)], fitted)
        import io, contextlib
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            cmd_normal_equations(args)
        ne = json.loads(buf.getvalue())
        print(f"| {d} | {ne['cond_A']:.2e} | {ne['cond_AtA']:.2e} | {ne['normal_equations']['coefficient_digits']:.1f} "
              f"| {ne['normal_equations']['fitted_digits']:.1f} | {ne['power_basis_svd_float64']['fitted_digits']:.1f} "
              f"| {cd:.1f} | {vd:.1f} | {ours['condition_number']:.2f} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    for name in ("fit", "normal-equations"):
        p = sub.add_parser(name)
        p.add_argument("csv")
        p.add_argument("--column", choices=["R", "T", "r", "t"], required=True)
        p.add_argument("--basis", choices=["full", "paper"], required=True)
        p.add_argument("--degree", type=int, required=True)
    p = sub.add_parser("digits-table")
    p.add_argument("csv")
    p.add_argument("--glassdb", required=True, help="path to the built glassdb binary")
    p.add_argument("--column", choices=["R", "T", "r", "t"], default="R")
    p.add_argument("--basis", choices=["full", "paper"], default="full")
    p.add_argument("--degrees", type=int, nargs="+", default=[2, 4, 6, 8, 10, 12])
    args = ap.parse_args()
    {"fit": cmd_fit, "normal-equations": cmd_normal_equations, "digits-table": cmd_digits_table}[args.cmd](args)


if __name__ == "__main__":
    main()
