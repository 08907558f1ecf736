//! Exact confirmation, `cargo xtask reference --claims FILE`: every entry of a claim that
//! agrees numerically is unrolled for each derived case up to `--links` links (sums
//! expanded, conditions and indices evaluated) into a sympy expression, and
//! `reference/prove.py` reduces claim − reference to derive.py's trigonometric normal
//! form: 0 proves the identity for that case.

use std::path::Path;
use std::process::{Command, Stdio};

use anyhow::{Context, bail};

use pendulum_reference::case::{Case, Kind};
use pendulum_reference::claims::check::{combinations, covered, quantity_of};
use pendulum_reference::claims::eval::{
    Bindings, EvalError, Quantity, Symbol, each_term, holds, index_value,
};
use pendulum_reference::claims::syntax::{Entry, Expr, Pos};
use pendulum_reference::claims::{Verdict, check_all, load};

/// Python's name of a quantity (`reference/prove.py`).
fn python_name(q: Quantity) -> String {
    match q {
        Quantity::MassMatrix => "M".into(),
        Quantity::Velocity => "c".into(),
        Quantity::Gravity => "k".into(),
        Quantity::Pivot => "d".into(),
        Quantity::Forces => "Q".into(),
        Quantity::Kinetic => "T".into(),
        Quantity::Potential => "U".into(),
        Quantity::Accelerations => "qdd".into(),
        Quantity::EulerLagrange => "EL".into(),
        Quantity::FreeRhs => "rhs".into(),
        Quantity::S => "S".into(),
        Quantity::A(r, c) => format!("A{}{}", r + 1, c + 1),
        Quantity::B(r, c) => format!("B{}{}", r + 1, c + 1),
        Quantity::C(r) => format!("C{}", r + 1),
    }
}

/// `e` for `n` links of `kind` with the indices `bound`, in derive.py's symbol names.
fn sympy(e: &Expr, bound: &mut Bindings, n: usize, kind: Kind) -> Result<String, EvalError> {
    let index = |i, bound: &Bindings| index_value(i, bound, n);
    let unknown = |name: &String, pos: &Pos, what: &str| EvalError {
        pos: *pos,
        found: name.clone(),
        message: format!("a known {what}"),
    };
    Ok(match e {
        Expr::Num(v) if v.fract() == 0.0 => format!("{}", *v as i64),
        Expr::Num(v) => format!("Rational('{v}')"),
        Expr::Sym { name, index: at, pos } => {
            let symbol = Symbol::named(name).ok_or_else(|| unknown(name, pos, "symbol"))?;
            let k = match at {
                Some(i) => index(i, bound)?,
                None => 0,
            };
            match symbol {
                Symbol::Theta => format!("th{k}"),
                Symbol::Phi => format!("ph{k}"),
                Symbol::ThetaDot => format!("dth{k}"),
                Symbol::PhiDot => format!("dph{k}"),
                Symbol::ThetaDdot => format!("ddth{k}"),
                Symbol::PhiDdot => format!("ddph{k}"),
                Symbol::Mass => format!("m{k}"),
                Symbol::TailMass if k as usize == n + 1 => "0".into(),
                Symbol::TailMass => {
                    let masses: Vec<String> = (k..=n as i64).map(|j| format!("m{j}")).collect();
                    format!("({})", masses.join(" + "))
                }
                Symbol::Length => format!("l{k}"),
                Symbol::Damping => format!("lam{k}"),
                Symbol::Torque if kind == Kind::Planar => format!("sig{k}"),
                Symbol::Torque => format!("sigth{k}"),
                Symbol::Gravity => "g".into(),
                Symbol::Links => n.to_string(),
                Symbol::Pi => "pi".into(),
                Symbol::Pivot(a) => format!("a{}", ["x", "y", "z"][a]),
            }
        }
        Expr::Ref { name, indices, pos } => {
            let q = Quantity::named(name).ok_or_else(|| unknown(name, pos, "matrix"))?;
            let at: Vec<String> = indices
                .iter()
                .map(|i| index(i, bound).map(|k| (k - 1).to_string()))
                .collect::<Result<_, _>>()?;
            format!("REF('{}', {})", python_name(q), at.join(", "))
        }
        Expr::Neg(a) => format!("(-{})", sympy(a, bound, n, kind)?),
        Expr::Add(a, b) => format!("({} + {})", sympy(a, bound, n, kind)?, sympy(b, bound, n, kind)?),
        Expr::Sub(a, b) => format!("({} - {})", sympy(a, bound, n, kind)?, sympy(b, bound, n, kind)?),
        Expr::Mul(a, b, _) => format!("({} * {})", sympy(a, bound, n, kind)?, sympy(b, bound, n, kind)?),
        Expr::Div(a, b) => format!("({} / {})", sympy(a, bound, n, kind)?, sympy(b, bound, n, kind)?),
        Expr::Pow(a, k) => format!("({} ** ({k}))", sympy(a, bound, n, kind)?),
        Expr::Call(f, a) => format!("{}({})", f.name(), sympy(a, bound, n, kind)?),
        Expr::Sum { .. } => {
            let mut terms = Vec::new();
            each_term(e, bound, n, |body, bound| {
                terms.push(sympy(body, bound, n, kind)?);
                Ok(())
            })?;
            if terms.is_empty() { "0".into() } else { format!("({})", terms.join(" + ")) }
        }
    })
}

/// One identity for prove.py, and where it came from.
struct Job {
    claim: usize,
    form: &'static str,
    json: serde_json::Value,
}

/// The identities of `entries` for every covered case up to `links` links.
fn jobs_of(entries: &[Entry], cases: &[&Case], links: usize, claim: usize, form: &'static str) -> Vec<Job> {
    let mut out = Vec::new();
    for case in cases.iter().filter(|c| c.links <= links) {
        let (kind, n) = (case.kind, case.links);
        for entry in entries {
            let Ok(quantity) = quantity_of(entry, kind) else { continue };
            let Ok(combos) = combinations(entry, &quantity.shape(kind, n), n) else { continue };
            for (at, mut bound) in combos {
                let branch = entry
                    .branches
                    .iter()
                    .find(|b| b.when.as_ref().is_none_or(|w| holds(w, &bound, n).unwrap_or(false)));
                let Some(branch) = branch else { continue };
                let Ok(expr) = sympy(&branch.value, &mut bound, n, kind) else { continue };
                let at: Vec<usize> = at.iter().map(|k| k - 1).collect();
                let json = serde_json::json!({
                    "kind": kind.as_str(), "n": n, "quantity": python_name(quantity), "at": at, "expr": expr,
                });
                out.push(Job { claim, form, json });
            }
        }
    }
    out
}

/// `cargo xtask reference --claims FILE`: proves, for every derived case up to `links`
/// links, each entry of every claim (and corrected form) that agrees numerically at
/// `states` random states. Fails if sympy refutes one (a numerical agreement that is not
/// an identity), or if python3 with sympy cannot run.
pub fn run(path: &Path, cases: &[Case], links: usize, states: usize, seed: u64) -> anyhow::Result<()> {
    let outcomes = check_all(path, load(path)?, cases, states, seed)?;
    crate::regen::check_python()?;
    let mut jobs = Vec::new();
    for (k, o) in outcomes.iter().enumerate() {
        let covering = covered(&o.claim, cases);
        if o.verdict() == Verdict::Agrees {
            jobs.extend(jobs_of(&o.claim.entries, &covering, links, k, "as written"));
        }
        if o.corrected().is_some_and(|(v, _)| v == Verdict::Agrees) {
            jobs.extend(jobs_of(&o.claim.corrected, &covering, links, k, "corrected"));
        }
    }
    let scratch = std::env::temp_dir().join(format!("pendulum-prove-{}", std::process::id()));
    std::fs::create_dir_all(&scratch).with_context(|| format!("creating {}", scratch.display()))?;
    let (input, output) = (scratch.join("jobs.json"), scratch.join("results.json"));
    let all: Vec<&serde_json::Value> = jobs.iter().map(|j| &j.json).collect();
    std::fs::write(&input, serde_json::to_string(&all)?)
        .with_context(|| format!("writing {}", input.display()))?;
    let reference = crate::workspace_root().join("reference");
    let status = Command::new("python3")
        .arg(reference.join("prove.py"))
        .args([&input, &output])
        .current_dir(&reference)
        .env("PYTHONHASHSEED", "0")
        .stdin(Stdio::null())
        .status()
        .context(
            "running python3 reference/prove.py (needs sympy: pip install -r reference/requirements.txt)",
        )?;
    if !status.success() {
        bail!("python3 reference/prove.py failed ({status}); see its output above");
    }
    let text = std::fs::read_to_string(&output).with_context(|| format!("reading {}", output.display()))?;
    let results: Vec<serde_json::Value> = serde_json::from_str(&text)?;
    let _ = std::fs::remove_dir_all(&scratch);
    println!("{}: exact confirmation up to {links} links (derive.py's normal form):", path.display());
    println!("| claim | form | identities | proven | not attempted | result |");
    println!("|---|---|---|---|---|---|");
    let mut refuted = Vec::new();
    for (k, o) in outcomes.iter().enumerate() {
        for form in ["as written", "corrected"] {
            let mine: Vec<&serde_json::Value> = jobs
                .iter()
                .zip(&results)
                .filter(|(j, _)| j.claim == k && j.form == form)
                .map(|(_, r)| r)
                .collect();
            if mine.is_empty() {
                continue;
            }
            let count = |what: &str| mine.iter().filter(|r| r["result"] == what).count();
            let (proven, skipped) = (count("proven"), count("skipped"));
            let bad: Vec<String> = mine
                .iter()
                .filter(|r| r["result"] == "refuted" || r["result"] == "error")
                .map(|r| {
                    format!("{}: {}", r["result"].as_str().unwrap_or("?"), r["why"].as_str().unwrap_or(""))
                })
                .collect();
            let result = match (bad.first(), proven) {
                (Some(first), _) => first.clone(),
                (None, 0) => "not attempted (accelerations of more than 2 degrees of freedom)".into(),
                (None, _) => "proven".into(),
            };
            println!("| {} | {form} | {} | {proven} | {skipped} | {result} |", o.claim.title, mine.len());
            refuted.extend(bad.into_iter().map(|b| format!("{} ({form}): {b}", o.claim.title)));
        }
    }
    if !refuted.is_empty() {
        bail!(
            "sympy does not confirm {} identit{}:\n  {}",
            refuted.len(),
            if refuted.len() == 1 { "y" } else { "ies" },
            refuted.join("\n  ")
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use pendulum_reference::claims::syntax::parse;

    #[test]
    fn sums_unroll_and_symbols_take_derive_names() {
        let claims = parse("claim \"x\"\nchain planar\nc[i] = sum(j = 1..n if j != i) M[max(i,j)] θ̇[j]^2 sin(θ[i] - θ[j]) / 2\n")
            .unwrap();
        let mut bound = Bindings::new();
        bound.insert("i".into(), 1);
        let text = sympy(&claims[0].entries[0].branches[0].value, &mut bound, 2, Kind::Planar).unwrap();
        assert_eq!(text, "(((((m2) * (dth2 ** (2))) * sin((th1 - th2))) / 2))");
    }
}
