#!/usr/bin/env python3
"""Symbolic reference for the N-link pendulum, derived from first principles.

For each case (planar n = 1..8, spatial n = 1..5) this script

1. writes the positions of the point masses as functions of time, with a moving
   pivot p(t) (sympy dynamicsymbols),
2. forms the kinetic energy T = 1/2 sum m_k |r_k'|^2, the potential energy
   U = sum m_k g (height of mass k) and L = T - U,
3. forms the Rayleigh dissipation D = 1/2 sum lam_i |u_i'|^2 with u_i' the rate of
   the unit link direction, u_i' = (r_i' - r_{i-1}')/l_i (r_0 = p), and the
   generalized forces Q_a = sig_a - dD/dqdot_a,
4. forms the Euler-Lagrange residual E_a = d/dt(dL/dqdot_a) - dL/dq_a - Q_a, taking
   the time derivative with .diff(t) and only then replacing the derivatives by
   plain symbols,
5. splits E = M qdd + c + k + d - Q (mass matrix, velocity terms, gravity terms,
   pivot terms, generalized forces) and checks a list of identities (see
   `check_case`),
6. differentiates the parts, with F = Q - c - k - d the force side of
   qdd = M^-1 F: dM/dq, dF/dq, dF/dqdot, dF/d(pivot acceleration), dF/dsig, each
   reduced to the normal form, checks them against objects computed another way (see
   `check_jacobians`) and writes one JSON file per case (format: reference/README.md).

Nothing here is taken from the seed document's printed formulas or from the Rust code,
except the expected form of Q in one cross-check (labelled as such in `check_case`),
which compares the derived Q with the Rust models' documented form afterwards.

Usage: python3 reference/derive.py [--out DIR] [--cases planar_n3,spatial_n2,...]
"""

import argparse
import json
import os
import sys
import time

import sympy
from sympy import Add, Integer, Mul, Pow, Rational, Symbol, cos, sin
from sympy.physics.vector import dynamicsymbols

SYMPY_VERSION = "1.14.0"
FORMAT = "pendulum-reference/2"
EQUATION = "mass_matrix * qdd + velocity_terms + gravity_terms + pivot_terms = generalized_forces"
PLANAR_LINKS = range(1, 9)
SPATIAL_LINKS = range(1, 6)

t = dynamicsymbols._t  # the time symbol the dynamicsymbols depend on


class DerivationError(Exception):
    """An identity that must hold did not."""


def require(condition, message):
    if not condition:
        raise DerivationError(message)


def real(name):
    return Symbol(name, real=True)


def positive(name):
    return Symbol(name, positive=True)


# ---------------------------------------------------------------------------
# Trigonometric canonical form.
#
# After the angles are replaced by plain symbols, every expression is a polynomial
# in sin(q_i), cos(q_i) and the other symbols (lengths appear with negative powers
# only in intermediate steps). We replace sin(q_i) -> S_i, cos(q_i) -> C_i, expand,
# and reduce modulo C_i^2 = 1 - S_i^2, so that C_i appears at most linearly in every
# monomial. This normal form is unique, so an identity holds iff the difference of
# both sides reduces to 0: equality checks below are exact, not numerical.
# ---------------------------------------------------------------------------


class Trig:
    """sin/cos of the angle symbols as plain symbols, and the reduction C^2 = 1 - S^2."""

    def __init__(self, angles):
        self.angles = list(angles)
        self.S = {q: real("sin_" + q.name) for q in self.angles}
        self.C = {q: real("cos_" + q.name) for q in self.angles}
        self.to_poly = {}
        for q in self.angles:
            self.to_poly[sin(q)] = self.S[q]
            self.to_poly[cos(q)] = self.C[q]
        self.c_to_s = {self.C[q]: self.S[q] for q in self.angles}
        # printer: plain symbol -> (function name, angle name)
        self.names = {}
        for q in self.angles:
            self.names[self.S[q]] = ("sin", q.name)
            self.names[self.C[q]] = ("cos", q.name)

    def poly(self, expr):
        """Replace sin/cos of angles by symbols and reduce to the normal form."""
        expr = expr.xreplace(self.to_poly)
        require(
            not any(q in expr.free_symbols for q in self.angles),
            "an angle appears outside sin/cos: " + str(expr)[:200],
        )
        return self.reduce(expr)

    def diff(self, expr, q):
        """d/dq by the chain rule through S = sin q, C = cos q, monomial by monomial:
        d/dq S^i C^j = i S^(i-1) C^(j+1) - j S^(i+1) C^(j-1); reduced to the normal form."""
        S, C = self.S[q], self.C[q]
        out = []
        for term in Add.make_args(sympy.expand(expr)):
            powers = term.as_powers_dict()
            i, j = powers.get(S, 0), powers.get(C, 0)
            if i:
                out.append(i * term * C / S)
            if j:
                out.append(-j * term * S / C)
        return self.reduce(Add(*out))

    def reduce(self, expr):
        expr = sympy.expand(expr)
        kept = []
        changed = []
        for term in Add.make_args(expr):
            powers = term.as_powers_dict()
            high = [(c, int(powers[c])) for c in self.c_to_s if powers.get(c, 0) >= 2]
            if not high:
                kept.append(term)
                continue
            new = term
            for c, e in high:
                s = self.c_to_s[c]
                new = new / c**e * c ** (e % 2) * (1 - s**2) ** (e // 2)
            changed.append(sympy.expand(new))
        return Add(*kept, *changed)


# ---------------------------------------------------------------------------
# Printer: sympy expression -> JSON expression tree (grammar: reference/README.md)
# ---------------------------------------------------------------------------


class Printer:
    def __init__(self, trig, allowed):
        self.trig = trig
        self.allowed = set(allowed)

    def __call__(self, expr):
        return self.tree(expr)

    def sorted_args(self, args):
        return sorted(args, key=sympy.default_sort_key)

    def tree(self, e):
        if isinstance(e, Integer):
            return int(e)
        if isinstance(e, Rational):
            require(e.q > 1, "bad rational " + str(e))
            return ["/", int(e.p), int(e.q)]
        if isinstance(e, Symbol):
            if e in self.trig.names:
                fn, name = self.trig.names[e]
                return [fn, name]
            require(e.name in self.allowed, "symbol %s is not listed under 'symbols'" % e.name)
            return e.name
        if isinstance(e, Add):
            return ["+"] + [self.tree(a) for a in self.sorted_args(e.args)]
        if isinstance(e, Mul):
            return ["*"] + [self.tree(a) for a in self.sorted_args(e.args)]
        if isinstance(e, Pow):
            require(isinstance(e.exp, Integer), "non-integer power: " + str(e))
            return ["^", self.tree(e.base), int(e.exp)]
        if isinstance(e, (sympy.sin, sympy.cos)):
            return [type(e).__name__, self.tree(e.args[0])]
        raise DerivationError(
            "cannot serialize sympy node %s (%s)" % (type(e).__name__, str(e)[:200])
        )


# ---------------------------------------------------------------------------
# Models
# ---------------------------------------------------------------------------


class Case:
    """Symbols and kinematics of one case; q are dynamicsymbols (functions of t)."""

    def __init__(self, kind, n):
        self.kind = kind
        self.n = n
        self.name = "%s_n%d" % (kind, n)
        idx = range(1, n + 1)
        self.m = [positive("m%d" % i) for i in idx]
        self.l = [positive("l%d" % i) for i in idx]
        self.g = positive("g")
        self.lam = [real("lam%d" % i) for i in idx]
        axes = ["x", "y"] if kind == "planar" else ["x", "y", "z"]
        self.axes = axes
        # pivot as functions of time, and the plain symbols its derivatives become
        self.p_fun = [dynamicsymbols("p" + a) for a in axes]
        self.p_sym = [real("p" + a) for a in axes]
        self.v_sym = [real("v" + a) for a in axes]
        self.a_sym = [real("a" + a) for a in axes]

        if kind == "planar":
            names = ["th%d" % i for i in idx]
            self.sig_names = ["sig%d" % i for i in idx]
        else:
            names = ["th%d" % i for i in idx] + ["ph%d" % i for i in idx]
            self.sig_names = ["sigth%d" % i for i in idx] + ["sigph%d" % i for i in idx]
        self.q_fun = [dynamicsymbols(nm) for nm in names]
        self.q = [real(nm) for nm in names]
        self.qd = [real("d" + nm) for nm in names]
        self.qdd = [real("dd" + nm) for nm in names]
        self.sig = [real(nm) for nm in self.sig_names]
        self.dof = len(self.q)

        # link unit directions u_i(t)
        if kind == "planar":
            self.u = [sympy.Matrix([sin(th), -cos(th)]) for th in self.q_fun]
        else:
            th, ph = self.q_fun[:n], self.q_fun[n:]
            self.u = [
                sympy.Matrix([sin(th[i]) * cos(ph[i]), sin(th[i]) * sin(ph[i]), -cos(th[i])])
                for i in range(n)
            ]
        p = sympy.Matrix(self.p_fun)
        self.r = []  # r_0 = p, r_k = p + sum_{j<=k} l_j u_j
        acc = p
        self.r.append(acc)
        for k in range(n):
            acc = acc + self.l[k] * self.u[k]
            self.r.append(acc)

        self.trig = Trig(self.q)

        # substitution of time functions by plain symbols, highest derivative first
        # (xreplace matches top-down, so Derivative(q(t), (t, 2)) is replaced whole)
        self.to_symbols = {}
        for f, s, v, a in zip(self.p_fun, self.p_sym, self.v_sym, self.a_sym):
            self.to_symbols[f.diff(t, 2)] = a
            self.to_symbols[f.diff(t)] = v
            self.to_symbols[f] = s
        for f, s, v, a in zip(self.q_fun, self.q, self.qd, self.qdd):
            self.to_symbols[f.diff(t, 2)] = a
            self.to_symbols[f.diff(t)] = v
            self.to_symbols[f] = s

    def symbolize(self, expr):
        expr = expr.xreplace(self.to_symbols)
        require(
            not expr.atoms(sympy.Derivative) and not expr.atoms(sympy.core.function.AppliedUndef),
            "a time function survived the substitution in " + self.name,
        )
        require(t not in expr.free_symbols, "t survived in " + self.name)
        return self.trig.poly(expr)

    def height(self, r):
        return r[1] if self.kind == "planar" else r[2]


def derive(case):
    """Returns a dict of normal-form sympy expressions for the case."""
    n, dof = case.n, case.dof
    rdot = [r.diff(t) for r in case.r]
    T = Rational(1, 2) * sum(case.m[k] * rdot[k + 1].dot(rdot[k + 1]) for k in range(n))
    U = sum(case.m[k] * case.g * case.height(case.r[k + 1]) for k in range(n))
    L = sympy.expand(T - U)

    # Rayleigh dissipation from the link direction rates computed from the positions
    D = 0
    for i in range(n):
        udot = (rdot[i + 1] - rdot[i]) / case.l[i]
        D += Rational(1, 2) * case.lam[i] * sympy.expand(udot.dot(udot))

    E_L = []  # d/dt dL/dqdot - dL/dq
    Q = []
    for a in range(dof):
        qf = case.q_fun[a]
        qfd = qf.diff(t)
        dL_dqd = L.diff(qfd)
        dL_dq = L.diff(qf)
        E_L.append(case.symbolize(dL_dqd.diff(t) - dL_dq))
        Q.append(case.symbolize(case.sig[a] - D.diff(qfd)))

    # energies with the pivot fixed at the origin and at rest
    at_rest = {f: 0 for f in case.p_fun}
    T0 = case.symbolize(T.subs(at_rest).doit())
    U0 = case.symbolize(U.subs(at_rest))

    # split E_L term by term (the normal form is expanded and unique). The split is
    # itself a check: every term must be one qdd times a coefficient without rates or
    # pivot acceleration (-> M), one pivot acceleration times a rate-free coefficient
    # (-> d), exactly two rates times a coefficient (-> c), or free of all of these (-> k)
    qdd, qd, acc = set(case.qdd), set(case.qd), set(case.a_sym)
    M = [[[] for _ in range(dof)] for _ in range(dof)]
    c = [[] for _ in range(dof)]
    k = [[] for _ in range(dof)]
    d = [[] for _ in range(dof)]
    forbidden = set(case.p_sym) | set(case.v_sym)
    for a in range(dof):
        leftover = E_L[a].free_symbols & forbidden
        require(
            not leftover,
            "%s: pivot position/velocity did not cancel in E_%d: %s" % (case.name, a, sorted(map(str, leftover))),
        )
        for term in Add.make_args(E_L[a]):
            pw = term.as_powers_dict()
            n_qdd = sum(pw.get(s, 0) for s in qdd)
            n_qd = sum(pw.get(s, 0) for s in qd)
            n_acc = sum(pw.get(s, 0) for s in acc)
            if n_qdd:
                require(
                    n_qdd == 1 and n_qd == 0 and n_acc == 0,
                    "%s: E not linear in qdd with a rate-free coefficient: %s" % (case.name, term),
                )
                b = next(i for i, s in enumerate(case.qdd) if pw.get(s, 0))
                M[a][b].append(term / case.qdd[b])
            elif n_acc:
                require(
                    n_acc == 1 and n_qd == 0,
                    "%s: pivot term not linear in a with a rate-free coefficient: %s" % (case.name, term),
                )
                d[a].append(term)
            elif n_qd:
                require(n_qd == 2, "%s: velocity term not quadratic in the rates: %s" % (case.name, term))
                c[a].append(term)
            else:
                k[a].append(term)
    M = [[Add(*e) for e in row] for row in M]
    c = [Add(*e) for e in c]
    k = [Add(*e) for e in k]
    d = [Add(*e) for e in d]
    out = dict(M=M, c=c, k=k, d=d, Q=Q, T=T0, U=U0)
    check_case(case, out)
    return out


def check_case(case, r):
    """Identities the derivation must satisfy; any failure aborts the run.

    Only identities that `derive` does not enforce by construction: the shape of each
    part (linear in qdd, linear in the pivot acceleration, quadratic in the rates) is
    asserted by the split itself; here the parts are compared with objects computed
    another way (T from the positions, Christoffel symbols of M, a potential written
    link by link, the pivot's inertial potential).
    """
    n, dof, trig = case.n, case.dof, case.trig
    M, c, k, d, Q, T0, U0 = (r[x] for x in ("M", "c", "k", "d", "Q", "T", "U"))

    # mass matrix: symmetric, non-zero diagonal
    for a in range(dof):
        require(M[a][a] != 0, "%s: M[%d][%d] = 0" % (case.name, a, a))
        for b in range(a + 1, dof):
            require(trig.reduce(M[a][b] - M[b][a]) == 0, "%s: M not symmetric at (%d,%d)" % (case.name, a, b))

    # T (pivot at rest, from the positions) = 1/2 qd^T M qd (M from the equations of motion)
    quad = sum(M[a][b] * case.qd[a] * case.qd[b] for a in range(dof) for b in range(dof)) / 2
    require(trig.reduce(quad - T0) == 0, "%s: T != qd^T M qd / 2" % case.name)

    # velocity terms from M alone (Christoffel symbols of the first kind):
    # c_a = sum_bc (dM_ab/dq_c - 1/2 dM_bc/dq_a) qd_b qd_c
    #     = sum_{b<=c} (1 if b < c else 1/2) G2_abc qd_b qd_c,
    # G2_abc = dM_ab/dq_c + dM_ac/dq_b - dM_bc/dq_a (twice the symbol; symmetric in b, c)
    dM = {}  # (a, b, c) with a <= b -> dM_ab/dq_c

    def dm(a, b, cc):
        key = (min(a, b), max(a, b), cc)
        if key not in dM:
            dM[key] = trig.diff(M[key[0]][key[1]], case.q[cc])
        return dM[key]

    for a in range(dof):
        terms = []
        for b in range(dof):
            for cc in range(b, dof):
                weight = 1 if b < cc else Rational(1, 2)
                G2 = dm(a, b, cc) + dm(a, cc, b) - dm(b, cc, a)
                terms.append(weight * G2 * case.qd[b] * case.qd[cc])
        require(
            trig.reduce(Add(*terms) - c[a]) == 0,
            "%s: velocity term %d != sum (dM_ab/dq_c - dM_bc/dq_a / 2) qd_b qd_c" % (case.name, a),
        )

    # gravity terms: the potential written directly from the heights of the links,
    # h(r_k) - h(p) = -sum_{i<=k} l_i cos(th_i) (both kinds), summed link by link
    U_links = potential_by_links(case)
    require(
        trig.reduce(U_links - U0) == 0,
        "%s: potential_energy != -g sum_i l_i cos(th_i) (m_i + ... + m_n)" % case.name,
    )
    check_gradient(case, U_links, k, "gravity term", "dU/dq")

    # pivot terms, equivalence principle: in the pivot's frame the drive is an inertial
    # force -m a, i.e. the potential U_a = sum m_k a . (r_k - p), and d = dU_a/dq
    U_acc = 0
    for i in range(n):
        rho = case.r[i + 1] - case.r[0]
        U_acc += case.m[i] * sum(a_ * x for a_, x in zip(case.a_sym, rho))
    check_gradient(case, case.symbolize(U_acc), d, "pivot term", "d(sum m_k a.(r_k - p))/dq")

    # Cross-check, not part of the derivation: the derived Q has exactly the form the
    # Rust models document, sig - lam thdot (planar, and theta of spatial) and
    # sig - lam sin^2(theta) phdot (phi of spatial). (Q free of the pivot needs no check
    # of its own: pdot cancels structurally in r_i' - r_{i-1}' before D is expanded.)
    for a in range(dof):
        i = a % n
        if case.kind == "planar" or a < n:
            expect = case.sig[a] - case.lam[i] * case.qd[a]
        else:
            expect = case.sig[a] - case.lam[i] * trig.S[case.q[i]] ** 2 * case.qd[a]
        require(
            trig.reduce(Q[a] - expect) == 0,
            "%s: Q_%d = %s differs from the Rust models' documented form %s" % (case.name, a, Q[a], expect),
        )


def potential_by_links(case):
    """U = -g sum_i l_i cos(th_i) (m_i + ... + m_n), from the heights of the links."""
    return -case.g * sum(
        case.l[i] * case.trig.C[case.q[i]] * sum(case.m[i:], Integer(0)) for i in range(case.n)
    )


def check_gradient(case, V, vec, what, formula):
    """Require vec[a] == dV/dq_a for every coordinate; V is a polynomial in the sin/cos
    symbols (no angle outside sin/cos), e.g. an expression from `Case.symbolize`."""
    for a in range(case.dof):
        grad = case.trig.diff(V, case.q[a])
        require(case.trig.reduce(grad - vec[a]) == 0, "%s: %s %d != %s" % (case.name, what, a, formula))


# ---------------------------------------------------------------------------
# Derivatives: what a check of the Jacobians of qdd = M^-1 F needs,
# F = Q - c - k - d (the force side)
# ---------------------------------------------------------------------------


def derive_jacobians(case, r):
    """Returns the derivatives of M and F, each entry reduced to the normal form.

    The angles enter through sin/cos only, so d/dq is `Trig.diff` (the chain rule on
    the normal form); rates, pivot accelerations and torques enter polynomially, so
    d/dqd, d/da and d/dsig are plain sympy derivatives of the polynomial. Nothing is
    re-derived from the Lagrangian: everything is a derivative of the case's own M, c,
    k, d, Q. Separate from `derive` (which reference/prove.py also uses).
    """
    dof, trig = case.dof, case.trig
    M, c, k, d, Q = (r[x] for x in ("M", "c", "k", "d", "Q"))
    F = [trig.reduce(Q[a] - c[a] - k[a] - d[a]) for a in range(dof)]

    def pdiff(expr, s):
        return trig.reduce(sympy.diff(expr, s))

    # dM[x][a][b] = dM_ab/dq_x, every entry from its own M_ab (not mirrored), so
    # that the symmetry check in `check_jacobians` compares independent results
    dM = [[[trig.diff(M[a][b], case.q[x]) for b in range(dof)] for a in range(dof)] for x in range(dof)]
    out = dict(
        dM=dM,
        Jq=[[trig.diff(F[a], case.q[x]) for x in range(dof)] for a in range(dof)],
        Jqd=[[pdiff(F[a], case.qd[x]) for x in range(dof)] for a in range(dof)],
        Jp=[[pdiff(F[a], s) for s in case.a_sym] for a in range(dof)],
        Js=[[pdiff(F[a], s) for s in case.sig] for a in range(dof)],
    )
    check_jacobians(case, r, out)
    return out


def check_jacobians(case, r, jac):
    """Identities the derivatives must satisfy; any failure aborts the run.

    The comparison objects come from the positions (Jacobians of the mass positions and
    link directions), the potential written link by link and the Christoffel symbols of
    the stored mass-matrix partials, not from F.
    """
    n, dof, trig = case.n, case.dof, case.trig
    c, Q = r["c"], r["Q"]
    dM, Jq, Jqd, Jp, Js = (jac[x] for x in ("dM", "Jq", "Jqd", "Jp", "Js"))
    qd = case.qd

    # kinematics, pivot-relative: rho_i = r_i - p (mass i), u_i (link i), their
    # Jacobians Jr[i][k][a] = d rho_ik/dq_a, Ju[i][k][a] = d u_ik/dq_a and the second
    # derivatives Hr[i][k][a][x] = d^2 rho_ik/dq_a dq_x
    space = len(case.axes)
    rho = [[case.symbolize(case.r[i + 1][kk] - case.r[0][kk]) for kk in range(space)] for i in range(n)]
    u = [[case.symbolize(case.u[i][kk]) for kk in range(space)] for i in range(n)]
    Jr = [[[trig.diff(rho[i][kk], q) for q in case.q] for kk in range(space)] for i in range(n)]
    Ju = [[[trig.diff(u[i][kk], q) for q in case.q] for kk in range(space)] for i in range(n)]
    Hr = [
        [[[trig.diff(Jr[i][kk][a], q) for q in case.q] for a in range(dof)] for kk in range(space)]
        for i in range(n)
    ]

    # mass-matrix partials: symmetric in (a, b), and equal to the derivative of
    # M_ab = sum_i m_i Jr_i,a . Jr_i,b (M from the positions), by the product rule:
    # dM_ab/dq_x = sum_i m_i (Hr_i,ax . Jr_i,b + Jr_i,a . Hr_i,bx)
    for x in range(dof):
        for a in range(dof):
            for b in range(a, dof):
                require(
                    trig.reduce(dM[x][a][b] - dM[x][b][a]) == 0,
                    "%s: dM_%d%d/dq_%d not symmetric in (a, b)" % (case.name, a, b, x),
                )
                kin = Add(*(
                    case.m[i] * (Hr[i][kk][a][x] * Jr[i][kk][b] + Jr[i][kk][a] * Hr[i][kk][b][x])
                    for i in range(n)
                    for kk in range(space)
                ))
                require(
                    trig.reduce(kin - dM[x][a][b]) == 0,
                    "%s: dM_%d%d/dq_%d != d/dq_%d sum_i m_i (d rho_i/dq_a).(d rho_i/dq_b)"
                    % (case.name, a, b, x, x),
                )

    # rate Jacobian: dF/dqd = -dc/dqd + dQ/dqd, with, independently,
    # dc_a/dqd_b = sum_c G2_abc qd_c (G2 from the stored partials, as in `check_case`)
    # and dQ_a/dqd_b = -d^2D/dqd_a dqd_b = -H_ab, H_ab = sum_i lam_i Ju_i,a . Ju_i,b
    # (D = 1/2 sum_i lam_i |u_i'|^2 with the link-direction rates u_i' = sum_a Ju_i,a qd_a)
    H = [[Add(*(case.lam[i] * Ju[i][kk][a] * Ju[i][kk][b] for i in range(n) for kk in range(space)))
          for b in range(dof)] for a in range(dof)]
    for a in range(dof):
        for b in range(dof):
            dc = Add(*((dM[cc][a][b] + dM[b][a][cc] - dM[a][b][cc]) * qd[cc] for cc in range(dof)))
            require(
                trig.reduce(Jqd[a][b] + dc + H[a][b]) == 0,
                "%s: dF_%d/dqd_%d != -sum_c G2_abc qd_c - d^2D/dqd_a dqd_b" % (case.name, a, b),
            )
        # Euler's theorem: c is homogeneous of degree 2 in the rates, Q - sig of degree 1
        euler = Add(*(Jqd[a][x] * qd[x] for x in range(dof)))
        require(
            trig.reduce(euler + 2 * c[a] - (Q[a] - case.sig[a])) == 0,
            "%s: sum_x dF_%d/dqd_x qd_x != -2 c + (Q - sig)" % (case.name, a),
        )

    # torque Jacobian: the identity (Q = sig - dD/dqd, nothing else depends on sig)
    for a in range(dof):
        for b in range(dof):
            require(Js[a][b] == (1 if a == b else 0), "%s: dF_%d/dsig_%d != delta" % (case.name, a, b))

    # pivot Jacobian: -d(d_a)/d(a_k) = -sum_i m_i d rho_ik/dq_a (the inertial force
    # -m_i a on each mass, mapped by the position Jacobian)
    for a in range(dof):
        for kk in range(space):
            expect = -Add(*(case.m[i] * Jr[i][kk][a] for i in range(n)))
            require(
                trig.reduce(Jp[a][kk] - expect) == 0,
                "%s: dF_%d/da_%s != -sum_i m_i d rho_i%s/dq_%d" % (case.name, a, case.axes[kk], case.axes[kk], a),
            )

    # angle Jacobian, entry by entry: dF/dq = dQ/dq - dc/dq - d(k + d)/dq with, each
    # computed without F,
    # - dQ_a/dq_x = -d/dq_x sum_b H_ab qd_b (Q = sig - H qd, H as above),
    # - dc_a/dq_x = sum_bc 1/2 dG2_abc/dq_x qd_b qd_c, from the second partials
    #   d^2M_ab/dq_c dq_x of the stored mass-matrix partials (Christoffel symbols),
    # - k + d = grad V, V = U + U_a, with U written link by link and
    #   U_a = sum_i m_i a . rho_i from the positions (pivot potential, as in `check_case`),
    #   so d(k + d)/dq is the Hessian of V
    V = potential_by_links(case) + Add(*(
        case.m[i] * case.a_sym[kk] * rho[i][kk] for i in range(n) for kk in range(space)
    ))
    gradV = [trig.diff(V, q) for q in case.q]
    H_qd = [trig.reduce(Add(*(H[a][b] * qd[b] for b in range(dof)))) for a in range(dof)]
    # (a, b, c, x), a <= b, c <= x -> d^2 M_ab / dq_c dq_x (dM is symmetric in (a, b),
    # checked above, and the chain rule on a polynomial commutes, so one of each)
    d2M = {}

    def d2m(a, b, cc, x):
        key = (min(a, b), max(a, b), min(cc, x), max(cc, x))
        if key not in d2M:
            d2M[key] = trig.diff(dM[key[2]][key[0]][key[1]], case.q[key[3]])
        return d2M[key]

    for a in range(dof):
        for x in range(dof):
            dc = []
            for b in range(dof):
                for cc in range(b, dof):
                    weight = 1 if b < cc else Rational(1, 2)
                    G2x = d2m(a, b, cc, x) + d2m(a, cc, b, x) - d2m(b, cc, a, x)
                    dc.append(weight * G2x * qd[b] * qd[cc])
            expect = -trig.diff(H_qd[a], case.q[x]) - Add(*dc) - trig.diff(gradV[a], case.q[x])
            require(
                trig.reduce(Jq[a][x] - expect) == 0,
                "%s: dF_%d/dq_%d != dQ/dq - sum_bc dG2_abc/dq_x qd_b qd_c / 2 - d^2(U + U_a)/dq dq"
                % (case.name, a, x),
            )


# ---------------------------------------------------------------------------
# Output
# ---------------------------------------------------------------------------


def compact(tree):
    return json.dumps(tree, separators=(",", ":"))


def render(case, r, jac):
    n = case.n
    symbols = [
        ("coordinates", [s.name for s in case.q]),
        ("rates", [s.name for s in case.qd]),
        ("masses", [s.name for s in case.m]),
        ("lengths", [s.name for s in case.l]),
        ("gravity", case.g.name),
        ("damping", [s.name for s in case.lam]),
        ("torques", case.sig_names),
        ("pivot_acceleration", [s.name for s in case.a_sym]),
    ]
    allowed = []
    for _, v in symbols:
        allowed += v if isinstance(v, list) else [v]
    pr = Printer(case.trig, allowed)

    lines = ["{"]
    header = [
        ("format", FORMAT),
        ("case", case.name),
        ("kind", case.kind),
        ("links", n),
        ("sympy_version", sympy.__version__),
        ("equation", EQUATION),
    ]
    for key, v in header:
        lines.append(" %s: %s," % (json.dumps(key), json.dumps(v)))
    lines.append(' "symbols": {')
    for i, (key, v) in enumerate(symbols):
        sep = "," if i + 1 < len(symbols) else ""
        lines.append("  %s: %s%s" % (json.dumps(key), compact(v), sep))
    lines.append(" },")

    def vector(key, exprs, last=False):
        lines.append(" %s: [" % json.dumps(key))
        for i, e in enumerate(exprs):
            lines.append("  " + compact(pr(e)) + ("," if i + 1 < len(exprs) else ""))
        lines.append(" ]" + ("" if last else ","))

    def nested(key, exprs, last=False):
        """A nested list, one bracket per line and one expression per line, each level
        indented by one more space."""

        def walk(x, indent, sep):
            if isinstance(x, list):
                lines.append(indent + "[")
                for i, y in enumerate(x):
                    walk(y, indent + " ", "," if i + 1 < len(x) else "")
                lines.append(indent + "]" + sep)
            else:
                lines.append(indent + compact(pr(x)) + sep)

        lines.append(" %s: [" % json.dumps(key))
        for i, x in enumerate(exprs):
            walk(x, "  ", "," if i + 1 < len(exprs) else "")
        lines.append(" ]" + ("" if last else ","))

    nested("mass_matrix", r["M"])
    vector("velocity_terms", r["c"])
    vector("gravity_terms", r["k"])
    vector("pivot_terms", r["d"])
    vector("generalized_forces", r["Q"])
    lines.append(' "kinetic_energy": %s,' % compact(pr(r["T"])))
    lines.append(' "potential_energy": %s,' % compact(pr(r["U"])))
    nested("mass_matrix_partials", jac["dM"])  # [x][a][b] = dM_ab/dq_x
    nested("force_jacobian_q", jac["Jq"])  # [a][x] = dF_a/dq_x
    nested("force_jacobian_qd", jac["Jqd"])  # [a][x] = dF_a/dqd_x
    nested("force_jacobian_pivot", jac["Jp"])  # [a][k] = dF_a/da_k
    nested("force_jacobian_torque", jac["Js"], last=True)  # [a][b] = dF_a/dsig_b
    lines.append("}")
    text = "\n".join(lines) + "\n"
    json.loads(text)  # well-formed
    return text


def all_cases():
    return [("planar", n) for n in PLANAR_LINKS] + [("spatial", n) for n in SPATIAL_LINKS]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    default_out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "cases")
    ap.add_argument("--out", default=default_out, help="output directory (default: reference/cases)")
    ap.add_argument("--cases", default=None, help="comma-separated subset, e.g. planar_n3,spatial_n2")
    ap.add_argument("--quiet", action="store_true", help="no per-case progress on stderr")
    args = ap.parse_args(argv)

    if sympy.__version__ != SYMPY_VERSION:
        sys.exit(
            "derive.py: sympy %s found, %s required (pip install -r reference/requirements.txt)"
            % (sympy.__version__, SYMPY_VERSION)
        )

    cases = all_cases()
    if args.cases:
        wanted = args.cases.split(",")
        known = {"%s_n%d" % c for c in cases}
        unknown = [w for w in wanted if w not in known]
        if unknown:
            sys.exit("derive.py: unknown case(s): %s" % ", ".join(unknown))
        cases = [c for c in cases if "%s_n%d" % c in wanted]

    os.makedirs(args.out, exist_ok=True)
    start = time.monotonic()
    for kind, n in cases:
        t0 = time.monotonic()
        case = Case(kind, n)
        try:
            r = derive(case)
            text = render(case, r, derive_jacobians(case, r))
        except DerivationError as e:
            sys.exit("derive.py: check failed: %s" % e)
        path = os.path.join(args.out, case.name + ".json")
        with open(path, "w", encoding="utf-8", newline="\n") as f:
            f.write(text)
        if not args.quiet:
            print(
                "%-12s %9d bytes  %6.2f s" % (case.name, len(text.encode()), time.monotonic() - t0),
                file=sys.stderr,
            )
    if not args.quiet:
        print("total %.2f s" % (time.monotonic() - start), file=sys.stderr)


if __name__ == "__main__":
    main()
