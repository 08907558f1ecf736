//! Claims files against the committed reference: deliberately wrong versions of correct
//! formulas, one per slip kind, each diagnosed as that slip with the right correction
//! (`tests/claims/slips.claims`); correct formulas in other but equivalent forms agree
//! (`tests/claims/equivalent.claims`); every kind of error in a file is reported with
//! `file:line:column`, the text there and what was expected, several together.

use std::path::{Path, PathBuf};

use xtask::case::{Case, load_all};
use xtask::claims::{Outcome, check_all, load};

const SEED: u64 = 20181223;

fn cases() -> Vec<Case> {
    load_all(&xtask::cases_dir()).expect("the committed reference")
}

fn file(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/claims").join(name)
}

fn outcomes(name: &str) -> Vec<Outcome> {
    let path = file(name);
    check_all(&path, load(&path).unwrap(), &cases(), 6, SEED).unwrap()
}

#[test]
fn equivalent_forms_of_correct_formulas_agree() {
    for o in outcomes("equivalent.claims") {
        assert_eq!(o.verdict().as_str(), "agrees", "{}: worst {:e}", o.claim.title, o.worst());
        assert!(o.worst() < 1e-14, "{}: {:e}", o.claim.title, o.worst());
        assert!(!o.cases.is_empty());
    }
}

#[test]
fn each_slip_is_diagnosed_and_corrected() {
    let expected = [
        ("the overall sign", "k[i] = M[i] g l[i] sin(theta[i])"),
        ("a constant factor: the reference is 1/2 × the claim", "T = 1 / 2 sum(i = 1..n) sum(j = 1..n)"),
        (
            "a constant factor and the sign: the reference is -2 × the claim",
            "qdd[2] = -2 thetadot[1] phidot[1] cot(theta[1])",
        ),
        (
            "the sign of one triangle: the branch `if i >= j`",
            "S[i,j] = -M[i] l[i] l[j] sin(theta[i] - theta[j])  if i >= j",
        ),
        ("sin for cos", "M[i,j] = M[max(i,j)] l[i] l[j] cos(theta[i] - theta[j])"),
        (
            "a coordinate confused with its rate: `theta[i]` should be `thetadot[i]`",
            "Q[i] = sigma[i] - lambda[i] thetadot[i]",
        ),
        ("transposed indices: i and j exchanged", "A12[i,j] = M[max(j,i)] l[j] l[i] sin(phi[i] - phi[j])"),
        ("an index off by one: `theta[2]` should be `theta[1]`", "k[1] = M[1] g l[1] sin(theta[1])"),
        (
            "the wrong tail-mass index: `M[min(i,j)]` should be `M[max(i,j)]`",
            "M[i,j] = M[max(i,j)] l[i] l[j] cos",
        ),
        (
            "a missing term: the reference has `+ sum(j = 1..i) M[i] l[i] l[j] thetadot[j]^2",
            "+ sum(j = 1..i) M[i]",
        ),
        // Issue 34: a sum stopping short is diagnosed at either end and at any depth.
        ("a missing term: the sum `sum(k = i+1..n) m[k]", "sum(k = i..n) m[k]"),
        ("a missing term: the sum `sum(k = max(i,j)+1..n) m[k]", "M[i,j] = sum(k = max(i,j)..n) m[k]"),
        ("a missing term: the sum `sum(i = 1..n-1)", "T = 1 / 2 sum(i = 1..n) sum(j = 1..n)"),
    ];
    let found = outcomes("slips.claims");
    assert_eq!(found.len(), expected.len());
    for (o, (slip, corrected)) in found.iter().zip(expected) {
        assert_eq!(o.verdict().as_str(), "disagrees", "{}", o.claim.title);
        let e = &o.entries[0];
        assert!(e.tally.first.as_deref().is_some_and(|f| f.contains("state")), "{}", o.claim.title);
        let d = e.diagnosis.as_ref().unwrap_or_else(|| panic!("{}: no diagnosis", o.claim.title));
        assert!(d.slip.starts_with(slip), "{}: {}", o.claim.title, d.slip);
        let text = d.corrected.render();
        assert!(text.contains(corrected), "{}: {text}", o.claim.title);
        // The corrected claim, as printed, parses and agrees.
        let path =
            std::env::temp_dir().join(format!("pendulum-claims-{}-corrected.claims", std::process::id()));
        let chains = if o.claim.chains.spatial { "spatial" } else { "planar" };
        let range = match o.claim.chains.high {
            Some(h) => format!("n = {}..{h}", o.claim.chains.low),
            None => format!("n >= {}", o.claim.chains.low),
        };
        std::fs::write(&path, format!("claim \"corrected\"\nchain {chains}, {range}\n{text}\n")).unwrap();
        let again = check_all(&path, load(&path).unwrap(), &cases(), 6, SEED).unwrap();
        assert_eq!(again[0].verdict().as_str(), "agrees", "{}: {text}", o.claim.title);
    }
}

/// Writes `text` as a claims file and returns the error message of checking it.
fn error(name: &str, text: &str) -> String {
    let path = std::env::temp_dir().join(format!("pendulum-claims-{}-{name}.claims", std::process::id()));
    std::fs::write(&path, text).unwrap();
    let message = match load(&path) {
        Err(e) => e.to_string(),
        Ok(claims) => match check_all(&path, claims, &cases(), 2, SEED) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("{name}: no error"),
        },
    };
    let display = path.display().to_string();
    assert!(message.contains(&format!("{display}:")), "{message}");
    message
}

#[test]
fn every_kind_of_error_names_its_place_and_what_was_expected() {
    let m = error("syntax", "claim \"a\"\nchain planar\nM[i,j] = cos(theta[i] - theta[j]\n");
    assert!(m.contains(":3:33: found the end of the line; expected `)` closing cos(…)"), "{m}");
    assert!(m.contains("    | M[i,j] = cos(theta[i] - theta[j]"), "{m}");
    let m = error("symbol", "claim \"a\"\nchain planar\nk[i] = M[i] gg l[i] sin(theta[i])\n");
    assert!(m.contains(":3:13: found gg; expected a known symbol: theta θ"), "{m}");
    let m = error("range", "claim \"a\"\nchain planar, n = 2..3\nk[i] = M[i] g l[i] sin(theta[i+1])\n");
    assert!(m.contains(":3:24: found theta[i+1] = theta[3]; expected an index in 1..2 (n = 2)"), "{m}");
    let m = error("entry", "claim \"a\"\nchain planar, n = 1..2\nM[3,3] = l[1]^2\n");
    assert!(
        m.contains(":3:1: found M[…3…]; expected an entry the quantity has: indices 1..1 for n = 1"),
        "{m}"
    );
    let m = error("rank", "claim \"a\"\nchain planar\nT[i] = 0\n");
    assert!(m.contains(":3:1: found T with 1 index; expected no index (T is a number)"), "{m}");
    let m = error("kind", "claim \"a\"\nchain spatial\nS[i,j] = 0\n");
    assert!(
        m.contains(
            ":3:1: found S; expected a quantity of spatial chains (S is defined for planar chains only)"
        ),
        "{m}"
    );
    let m = error("unbound", "claim \"a\"\nchain planar\nk[i] = l[j]\n");
    assert!(m.contains(":3:10: found j; expected an index bound here"), "{m}");
    let m = error("empty", "claim \"a\"\nchain planar\n");
    assert!(m.contains(":1:1: found claim \"a\"; expected at least one entry"), "{m}");
    // Several errors, in several claims, together.
    let m = error("several", "claim \"a\"\nchain wobbly\nclaim \"b\"\nchain planar\nk[i] = 2 $\nclaim c\n");
    assert!(m.starts_with("3 errors in "), "{m}");
    for place in [":2:7: found wobbly; expected planar or spatial", ":5:10: found $", ":6:7: found c"] {
        assert!(m.contains(place), "{place} in {m}");
    }
}

/// `reference/claims/seed.claims`: the document's equations a claims file states. Every
/// verdict is the one `reference/ERRATA.md` records for that equation, and the
/// disagreements get the diagnoses it describes.
#[test]
fn the_seed_claims_match_the_errata() {
    use xtask::verify::document::errata::{errata_path, parse_summary};
    let summary = parse_summary(&std::fs::read_to_string(errata_path()).unwrap()).unwrap();
    let path = xtask::workspace_root().join("reference/claims/seed.claims");
    let found = check_all(&path, load(&path).unwrap(), &cases(), 6, SEED).unwrap();
    assert_eq!(found.len(), 33, "32 equations, eq 12 planar and spatial");
    for o in &found {
        // "Eq 24 S: …" → "24 S"; "Eq 12: U (spatial…)" → "12".
        let equation = o.claim.title.trim_start_matches("Eq ").split(':').next().unwrap();
        let recorded = summary.iter().find(|(e, _)| e == equation).map(|(_, v)| v.as_str());
        assert_eq!(Some(o.verdict().as_str()), recorded, "eq {equation}: worst {:e}", o.worst());
    }
    let diagnoses = |equation: &str| -> Vec<String> {
        let o = found.iter().find(|o| o.claim.title.starts_with(&format!("Eq {equation}:"))).unwrap();
        o.entries.iter().filter_map(|e| e.diagnosis.as_ref().map(|d| d.slip.clone())).collect()
    };
    assert_eq!(diagnoses("23"), ["the sign of one triangle: the branch `if i >= j` has the wrong sign"]);
    assert_eq!(diagnoses("24 S").len(), 4, "the four cos of eq 24's S");
    assert!(diagnoses("24 S").iter().all(|d| d.starts_with("cos for sin")));
    for equation in ["38", "39", "42"] {
        assert_eq!(diagnoses(equation), ["a constant factor: the reference is 2 × the claim"]);
    }
    assert_eq!(diagnoses("43"), ["a constant factor and the sign: the reference is -2 × the claim"]);
    assert_eq!(diagnoses("50"), ["an index off by one: `θ[1]` should be `θ[2]` (+1)"]);
    let forty_one = diagnoses("41");
    assert_eq!(forty_one, ["a coordinate confused with its rate: every `θ[j]` should be `θ̇[j]`"]);
    // Two slips at once (cos for sin and a missing θ̇_d): not one common slip.
    assert!(diagnoses("15").is_empty());
    for o in &found {
        if let Some((verdict, worst)) = o.corrected() {
            assert_eq!(verdict.as_str(), "agrees", "{}: the corrected form, worst {worst:e}", o.claim.title);
        }
    }
}

/// `cargo xtask reference --claims`: sympy proves an identity and refutes a claim that
/// only agrees to round-off. Needs python3 with sympy; skipped without it unless
/// `PENDULUM_SYMPY_TEST=require` (as `.ci/run` sets).
#[test]
fn sympy_proves_identities_and_refutes_a_near_miss() {
    let has_sympy = std::process::Command::new("python3")
        .args(["-c", "import sympy"])
        .status()
        .is_ok_and(|s| s.success());
    if !has_sympy {
        assert!(std::env::var("PENDULUM_SYMPY_TEST").as_deref() != Ok("require"), "no python3 with sympy");
        eprintln!("no python3 with sympy: the exact confirmation is not tested");
        return;
    }
    let found = outcomes("almost.claims");
    assert!(found.iter().all(|o| o.verdict().as_str() == "agrees"), "both agree numerically");
    let error =
        xtask::claims_proof::run(&file("almost.claims"), &cases(), 2, 6, SEED).unwrap_err().to_string();
    assert!(error.starts_with("sympy does not confirm 2 identities:"), "{error}");
    assert!(error.contains("nearly the mass matrix (as written): refuted"), "{error}");
    assert!(!error.contains("velocity terms"), "the identity is proven: {error}");
}
