"""Exact confirmation of claims: `cargo xtask reference --claims FILE` writes one job per
entry of a claim that agreed numerically (its value unrolled for one case, as a sympy
expression in derive.py's symbol names), and this script proves or refutes each one:
the case is derived from first principles as in derive.py, the reference quantity is
formed from it, and claim - reference is reduced to derive.py's trigonometric normal
form (sin/cos of each angle as symbols, cos^2 = 1 - sin^2), which is 0 iff the identity
holds.

    python3 reference/prove.py JOBS.json RESULTS.json
"""

import json
import sys

import sympy
from sympy import expand_trig, numer, together

from derive import Case, derive


def coefficient(expr, *rates):
    """The coefficient of the product of `rates` (a rate twice: its square) in `expr`."""
    expr = sympy.expand(expr)
    if len(rates) == 2 and rates[0] == rates[1]:
        return expr.coeff(rates[0], 2)
    for rate in rates:
        expr = expr.coeff(rate, 1)
    return expr


def reference(case, r, quantity, at):
    """The reference's entry `at` (0-based) of `quantity`, or None if not attempted."""
    n, qd = case.n, case.qd
    i = at[0] if at else None
    j = at[1] if len(at) > 1 else None
    block = {"1": 0, "2": 1}
    if quantity == "M":
        return r["M"][i][j]
    if quantity in ("c", "k", "d", "Q"):
        return r[quantity][i]
    if quantity in ("T", "U"):
        return r[quantity]
    if quantity == "EL":
        return sum(r["M"][i][b] * case.qdd[b] for b in range(case.dof)) + r["c"][i] + r["k"][i]
    if quantity == "rhs":
        return -(r["c"][i] + r["k"][i])
    if quantity == "qdd":
        # The free accelerations M^-1 (-c - k), entry i by Cramer's rule: small chains only.
        if case.dof > 2:
            return None
        M = sympy.Matrix(r["M"])
        replaced = M.copy()
        replaced[:, i] = sympy.Matrix([-(r["c"][a] + r["k"][a]) for a in range(case.dof)])
        return replaced.det() / M.det()
    if quantity == "S":
        return -coefficient(r["c"][i], qd[j], qd[j])
    if quantity[0] == "A":
        return r["M"][block[quantity[1]] * n + i][block[quantity[2]] * n + j]
    if quantity[0] == "B":
        row, col = block[quantity[1]] * n + i, block[quantity[2]] * n + j
        return -coefficient(r["c"][row], qd[col], qd[col])
    if quantity[0] == "C":
        return coefficient(r["c"][block[quantity[1]] * n + i], qd[j], qd[n + j])
    return None


def prove(case, r, job):
    ref = reference(case, r, job["quantity"], job["at"])
    if ref is None:
        return {"result": "skipped", "why": "%s of %d degrees of freedom: not attempted" % (job["quantity"], case.dof)}
    names = {s.name: s for s in case.q + case.qd + case.qdd + case.m + case.l + case.lam + case.sig + case.a_sym}
    names["g"] = case.g
    names["REF"] = lambda quantity, *at: reference(case, r, quantity, list(at))
    claim = sympy.sympify(job["expr"], locals=names)
    # tan and cot as sin and cos, so that the angles appear inside sin and cos only
    claim = claim.replace(sympy.cot, lambda a: sympy.cos(a) / sympy.sin(a))
    claim = claim.replace(sympy.tan, lambda a: sympy.sin(a) / sympy.cos(a))
    difference = together(expand_trig(claim - ref))
    residual = case.trig.poly(numer(difference))
    if residual == 0:
        return {"result": "proven"}
    return {"result": "refuted", "why": "the numerator of claim - reference is " + str(residual)[:200]}


def main(argv):
    jobs_path, results_path = argv[1], argv[2]
    with open(jobs_path, encoding="utf-8") as f:
        jobs = json.load(f)
    derived = {}
    results = []
    for job in jobs:
        key = (job["kind"], job["n"])
        if key not in derived:
            case = Case(*key)
            derived[key] = (case, derive(case))
        case, r = derived[key]
        try:
            results.append(prove(case, r, job))
        except Exception as e:  # a claim sympy cannot reduce is reported, not fatal
            results.append({"result": "error", "why": "%s: %s" % (type(e).__name__, str(e)[:200])})
    with open(results_path, "w", encoding="utf-8") as f:
        json.dump(results, f)


if __name__ == "__main__":
    main(sys.argv)
