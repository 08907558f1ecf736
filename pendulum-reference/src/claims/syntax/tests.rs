//! Parser tests: what parses, and the errors with line and column.

use super::*;

fn one(text: &str) -> Claim {
    let mut claims = parse(text).unwrap_or_else(|e| panic!("{e:?}"));
    assert_eq!(claims.len(), 1);
    claims.remove(0)
}

#[test]
fn a_claim_parses_and_prints_back() {
    let c = one("# a comment\nclaim \"Eq 23\"   # trailing\n  chain planar, n = 1..8\n  \
         S[i,j] = M[i] l[i] l[j] sin(θ[i] - θ[j])  if i >= j\n         = M[j] l[j] l[i] sin(θ[j]-θ[i]) otherwise\n");
    assert_eq!(c.title, "Eq 23");
    assert_eq!(c.chains, Chains { spatial: false, low: 1, high: Some(8) });
    let e = &c.entries[0];
    assert_eq!((e.quantity.as_str(), e.indices.len(), e.branches.len()), ("S", 2, 2));
    assert_eq!(
        e.render(),
        "S[i,j] = M[i] l[i] l[j] sin(θ[i] - θ[j])  if i >= j\n       = M[j] l[j] l[i] sin(θ[j] - θ[i])  otherwise"
    );
    // The printed form parses to the same entry.
    let again = one(&format!("claim \"x\"\nchain planar\n{}\n", e.render()));
    assert_eq!(again.entries[0].render(), e.render());
}

#[test]
fn precedence_sums_powers_and_continuations() {
    let c = one("claim \"T\"\nchain spatial n >= 2\nT = 1/2 sum(i = 1..n) m[i] v[i]^2\n  + 2 * -g\n");
    assert_eq!(c.entries[0].render(), "T = 1 / 2 sum(i = 1..n) m[i] v[i]^2 + 2 * (-g)");
    assert_eq!(c.chains, Chains { spatial: true, low: 2, high: None });
    let e = one("claim \"p\"\nchain planar\nk[i] = (a + b) c^-1 - d e\n").entries.remove(0);
    assert_eq!(e.render(), "k[i] = (a + b) c^-1 - d e");
    // A signed right factor keeps its bracket (else it would read as a subtraction).
    let e = one("claim \"s\"\nchain planar\nk[i] = 2 (-l[i] g)\n").entries.remove(0);
    assert_eq!(e.render(), "k[i] = 2 (-l[i] g)");
    let e = one("claim \"m\"\nchain planar\nM[i,j] = m[max(i,j)+1] 1.5e-3\n").entries.remove(0);
    assert_eq!(e.render(), "M[i,j] = m[max(i,j)+1] 0.0015");
}

#[test]
fn errors_say_where_what_and_what_was_expected() {
    let errors = parse("chain planar\nclaim \"a\"\nchain wobbly\nclaim b\nclaim \"c\"\nchain planar\nM[i,j] = sin(θ[i]\nT = 3 $\n")
        .unwrap_err();
    let got: Vec<(usize, usize, &str)> =
        errors.iter().map(|e| (e.pos.line, e.pos.col, e.found.as_str())).collect();
    assert_eq!(
        got,
        [(1, 1, "chain"), (3, 7, "wobbly"), (4, 7, "b"), (7, 18, "the end of the line"), (8, 7, "$"),]
    );
    assert!(errors[1].message.contains("planar or spatial"));
    assert!(errors[3].message.contains("`)` closing sin"), "{}", errors[3].message);
}
