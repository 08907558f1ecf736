//! One sympy reference case (`reference/cases/*.json`): loading with validation, and
//! evaluation of its equations of motion at a numeric state.
//!
//! A case holds, for one kind and number of links, the equations of motion
//! `mass_matrix · q̈ + velocity_terms + gravity_terms + pivot_terms = generalized_forces`
//! as expression trees ([`crate::expr`]); the format is described in
//! `reference/README.md`.

use std::{
    fmt,
    path::{Path, PathBuf},
};

use anyhow::{Context, Result, anyhow, bail, ensure};
use nalgebra::{DMatrix, DVector};
use serde_json::{Map, Value};

use crate::expr::{Expr, Scaled, Symbols};

mod partials;

use partials::Partials;
pub use partials::PartialsAt;

/// The format string every case file must carry.
pub const FORMAT: &str = "pendulum-reference/2";

/// The equation every case file must state, in its sign convention.
pub const EQUATION: &str =
    "mass_matrix * qdd + velocity_terms + gravity_terms + pivot_terms = generalized_forces";

/// Planar or spatial chain.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Kind {
    /// Coordinates `θ_1..θ_n`, pivot acceleration `(a_x, a_y)`.
    Planar,
    /// Coordinates `(θ_1..θ_n, φ_1..φ_n)`, pivot acceleration `(a_x, a_y, a_z)`.
    Spatial,
}

impl Kind {
    /// Number of generalized coordinates of an `links`-link chain: `n` or `2n`.
    pub fn dof(self, links: usize) -> usize {
        match self {
            Kind::Planar => links,
            Kind::Spatial => 2 * links,
        }
    }

    /// Dimension of the space (components of the pivot acceleration): 2 or 3.
    pub fn space(self) -> usize {
        match self {
            Kind::Planar => 2,
            Kind::Spatial => 3,
        }
    }

    /// `"planar"` or `"spatial"`, as in the case files.
    pub fn as_str(self) -> &'static str {
        match self {
            Kind::Planar => "planar",
            Kind::Spatial => "spatial",
        }
    }
}

impl fmt::Display for Kind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A chain's parameters, as plain vectors (one entry per link).
#[derive(Debug, Clone, PartialEq)]
pub struct Params {
    /// Point masses `m_i`, kg.
    pub masses: Vec<f64>,
    /// Rod lengths `l_i`, m.
    pub lengths: Vec<f64>,
    /// Gravitational acceleration `g`, m/s².
    pub gravity: f64,
    /// Damping coefficients `λ_i`, N·m·s.
    pub damping: Vec<f64>,
}

/// A state and the inputs at one instant, as plain vectors.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// Coordinates `q` (rad), `dof` entries.
    pub q: Vec<f64>,
    /// Rates `q̇` (rad/s), `dof` entries.
    pub qd: Vec<f64>,
    /// Generalized torques `σ` (N·m), `dof` entries.
    pub torque: Vec<f64>,
    /// Pivot acceleration `p̈` (m/s²), 2 (planar) or 3 (spatial) entries.
    pub pivot_acceleration: Vec<f64>,
}

/// Every quantity of a case evaluated at one state (or, from
/// [`Case::evaluate_with_scales`], the absolute scale of each entry).
#[derive(Debug, Clone, PartialEq)]
pub struct Evaluated {
    /// `M(q)`, dof × dof.
    pub mass_matrix: DMatrix<f64>,
    /// `c(q, q̇)`.
    pub velocity_terms: DVector<f64>,
    /// `k(q)`.
    pub gravity_terms: DVector<f64>,
    /// `d(q, p̈)`.
    pub pivot_terms: DVector<f64>,
    /// `Q(q, q̇, σ)`.
    pub generalized_forces: DVector<f64>,
    /// `T`.
    pub kinetic_energy: f64,
    /// `U`.
    pub potential_energy: f64,
}

impl Evaluated {
    /// The right-hand side `Q − c − k − d` of `M q̈ = Q − c − k − d`.
    pub fn rhs(&self) -> DVector<f64> {
        &self.generalized_forces - &self.velocity_terms - &self.gravity_terms - &self.pivot_terms
    }
}

/// Where each symbol category starts in the slot slice (in file order).
#[derive(Debug, Clone, PartialEq)]
struct Layout {
    coordinates: usize,
    rates: usize,
    masses: usize,
    lengths: usize,
    gravity: usize,
    damping: usize,
    torques: usize,
    pivot_acceleration: usize,
    len: usize,
}

/// A loaded, validated reference case.
#[derive(Debug, Clone, PartialEq)]
pub struct Case {
    /// The case's name, e.g. `"planar_n3"` (equal to the file's stem).
    pub name: String,
    /// Planar or spatial.
    pub kind: Kind,
    /// Number of links `n`.
    pub links: usize,
    /// The file it was loaded from.
    pub path: PathBuf,
    layout: Layout,
    /// Row-major, dof × dof.
    mass_matrix: Vec<Expr>,
    velocity_terms: Vec<Expr>,
    gravity_terms: Vec<Expr>,
    pivot_terms: Vec<Expr>,
    generalized_forces: Vec<Expr>,
    kinetic_energy: Expr,
    potential_energy: Expr,
    /// The stored derivatives.
    partials: Partials,
}

/// The symbol categories under `"symbols"`, in slot order, with their expected lengths.
const CATEGORIES: [&str; 8] =
    ["coordinates", "rates", "masses", "lengths", "gravity", "damping", "torques", "pivot_acceleration"];

impl Case {
    /// Loads and validates a case file.
    ///
    /// Errors (each naming the file, and the case once known) for unreadable or
    /// malformed JSON, a wrong `"format"`, an unknown `"kind"`, a `"case"` name that is
    /// not the file's stem, a symbol list of the wrong length (coordinates, rates and
    /// torques need `dof` names, masses, lengths and damping `n`, the pivot acceleration
    /// 2 or 3), a duplicate symbol, an array whose dimensions do not match `dof`, and
    /// any expression error ([`Expr::parse`]).
    pub fn load(path: &Path) -> Result<Case> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).with_context(|| format!("{file}: cannot read"))?;
        let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or_default();
        Self::parse(&text, &file, stem)
    }

    /// A case from the text of its file, named `file` in errors, whose name must be `stem`
    /// (the file's name without `.json`): the checks of [`load`](Self::load).
    pub fn parse(text: &str, file: &str, stem: &str) -> Result<Case> {
        let json: Value = serde_json::from_str(text).with_context(|| format!("{file}: invalid JSON"))?;
        let root = json.as_object().ok_or_else(|| anyhow!("{file}: expected a JSON object"))?;
        let get = |key: &str| root.get(key).ok_or_else(|| anyhow!("{file}: missing key {key:?}"));
        let string = |key: &str| {
            get(key)?.as_str().map(str::to_owned).ok_or_else(|| anyhow!("{file}: {key:?} must be a string"))
        };

        let format = string("format")?;
        ensure!(format == FORMAT, "{file}: format is {format:?}, expected {FORMAT:?}");
        let name = string("case")?;
        let at = format!("{file}: case {name}");
        ensure!(stem == name, "{at}: the file is named {stem:?}; expected the case name");
        let kind = match string("kind")?.as_str() {
            "planar" => Kind::Planar,
            "spatial" => Kind::Spatial,
            other => bail!("{at}: unknown kind {other:?} (expected \"planar\" or \"spatial\")"),
        };
        let links = get("links")?
            .as_u64()
            .filter(|&n| n >= 1)
            .ok_or_else(|| anyhow!("{at}: \"links\" must be a positive integer"))?
            as usize;
        // The deriving sympy version is informational (`cargo xtask reference --check`
        // is what ties the files to sympy), but must be there.
        string("sympy_version").with_context(|| at.clone())?;
        let equation = string("equation").with_context(|| at.clone())?;
        ensure!(equation == EQUATION, "{at}: the equation is {equation:?}, expected {EQUATION:?}");
        let dof = kind.dof(links);

        let (symbols, layout) = symbol_table(get("symbols")?, kind, links, &at)?;
        let expr = |key: &str| -> Result<Expr> { Expr::parse(get(key)?, &symbols, &format!("{at}: {key}")) };
        let vector = |key: &str| -> Result<Vec<Expr>> {
            let items = array(get(key)?, dof, &format!("{at}: {key}"))?;
            items
                .iter()
                .enumerate()
                .map(|(i, e)| Expr::parse(e, &symbols, &format!("{at}: {key}[{i}]")))
                .collect()
        };
        let mut mass_matrix = Vec::with_capacity(dof * dof);
        for (i, row) in array(get("mass_matrix")?, dof, &format!("{at}: mass_matrix"))?.iter().enumerate() {
            for (j, e) in array(row, dof, &format!("{at}: mass_matrix[{i}]"))?.iter().enumerate() {
                mass_matrix.push(Expr::parse(e, &symbols, &format!("{at}: mass_matrix[{i}][{j}]"))?);
            }
        }
        let partials = Partials::load(root, &symbols, dof, kind.space(), &at)?;
        Ok(Case {
            partials,
            velocity_terms: vector("velocity_terms")?,
            gravity_terms: vector("gravity_terms")?,
            pivot_terms: vector("pivot_terms")?,
            generalized_forces: vector("generalized_forces")?,
            kinetic_energy: expr("kinetic_energy")?,
            potential_energy: expr("potential_energy")?,
            mass_matrix,
            name,
            kind,
            links,
            path: PathBuf::from(file),
            layout,
        })
    }

    /// Number of generalized coordinates: `n` planar, `2n` spatial.
    pub fn dof(&self) -> usize {
        self.kind.dof(self.links)
    }

    /// Every expression, in the order [`Case::assemble`] takes their results:
    /// mass matrix (row-major), velocity, gravity and pivot terms, generalized forces,
    /// kinetic and potential energy.
    fn exprs(&self) -> impl Iterator<Item = &Expr> {
        self.mass_matrix
            .iter()
            .chain(&self.velocity_terms)
            .chain(&self.gravity_terms)
            .chain(&self.pivot_terms)
            .chain(&self.generalized_forces)
            .chain([&self.kinetic_energy, &self.potential_energy])
    }

    /// The slot values of `params` and `point`, in the symbol table's order.
    ///
    /// Panics, naming the vector, if a length does not fit the case.
    fn slots(&self, params: &Params, point: &Point) -> Vec<f64> {
        let (n, dof, space) = (self.links, self.dof(), self.kind.space());
        let parts: [(&str, &[f64], usize, usize); 8] = [
            ("q", &point.q, dof, self.layout.coordinates),
            ("qd", &point.qd, dof, self.layout.rates),
            ("masses", &params.masses, n, self.layout.masses),
            ("lengths", &params.lengths, n, self.layout.lengths),
            ("gravity", std::slice::from_ref(&params.gravity), 1, self.layout.gravity),
            ("damping", &params.damping, n, self.layout.damping),
            ("torque", &point.torque, dof, self.layout.torques),
            ("pivot_acceleration", &point.pivot_acceleration, space, self.layout.pivot_acceleration),
        ];
        let mut slots = vec![0.0; self.layout.len];
        for (what, values, expected, start) in parts {
            assert_eq!(
                values.len(),
                expected,
                "{}: {what} has {} entries, expected {expected}",
                self.name,
                values.len()
            );
            slots[start..start + expected].copy_from_slice(values);
        }
        slots
    }

    /// The quantities from one number per expression, in [`Case::exprs`] order.
    fn assemble(&self, mut numbers: impl Iterator<Item = f64>) -> Evaluated {
        let dof = self.dof();
        let mass_matrix = DMatrix::from_row_iterator(dof, dof, numbers.by_ref().take(dof * dof));
        let mut vector = || DVector::from_iterator(dof, numbers.by_ref().take(dof));
        let (velocity_terms, gravity_terms, pivot_terms, generalized_forces) =
            (vector(), vector(), vector(), vector());
        let mut scalar = || numbers.next().expect("one number per expression");
        let (kinetic_energy, potential_energy) = (scalar(), scalar());
        Evaluated {
            mass_matrix,
            velocity_terms,
            gravity_terms,
            pivot_terms,
            generalized_forces,
            kinetic_energy,
            potential_energy,
        }
    }

    /// Every quantity of the case at `params` and `point`.
    ///
    /// Panics if a vector of `params` or `point` has the wrong length for the case.
    pub fn evaluate(&self, params: &Params, point: &Point) -> Evaluated {
        let slots = self.slots(params, point);
        self.assemble(self.exprs().map(|e| e.eval(&slots)))
    }

    /// Every quantity of the case at `params` and `point`, and the absolute scale
    /// ([`Scaled`]) of every entry: the size of its round-off, against which
    /// implementations are compared. Walks each expression once.
    ///
    /// Panics if a vector of `params` or `point` has the wrong length for the case.
    pub fn evaluate_with_scales(&self, params: &Params, point: &Point) -> (Evaluated, Evaluated) {
        let slots = self.slots(params, point);
        let both: Vec<Scaled> = self.exprs().map(|e| e.eval_with_scale(&slots)).collect();
        (self.assemble(both.iter().map(|x| x.v)), self.assemble(both.iter().map(|x| x.s)))
    }

    /// The stored derivatives (`∂M/∂q`, the force side's Jacobians) at `params` and
    /// `point`, and their absolute scales.
    ///
    /// Panics if a vector of `params` or `point` has the wrong length for the case.
    pub fn partials_with_scales(&self, params: &Params, point: &Point) -> (PartialsAt, PartialsAt) {
        self.partials.evaluate_with_scales(&self.slots(params, point), self.dof(), self.kind.space())
    }

    /// The accelerations `q̈` solving `M q̈ = Q − c − k − d` (by LU with partial pivoting;
    /// NaN entries if `M` is singular).
    pub fn accelerations(&self, params: &Params, point: &Point) -> DVector<f64> {
        let e = self.evaluate(params, point);
        let rhs = e.rhs();
        e.mass_matrix.lu().solve(&rhs).unwrap_or_else(|| DVector::from_element(self.dof(), f64::NAN))
    }
}

/// `value` as an array of exactly `len` items.
fn array<'a>(value: &'a Value, len: usize, at: &str) -> Result<&'a Vec<Value>> {
    let items = value.as_array().ok_or_else(|| anyhow!("{at}: expected an array of {len} entries"))?;
    ensure!(items.len() == len, "{at}: has {} entries, expected {len}", items.len());
    Ok(items)
}

/// Builds the symbol table from `"symbols"`, checking each list's length.
fn symbol_table(value: &Value, kind: Kind, links: usize, at: &str) -> Result<(Symbols, Layout)> {
    let object: &Map<String, Value> =
        value.as_object().ok_or_else(|| anyhow!("{at}: \"symbols\" must be an object"))?;
    let (n, dof) = (links, kind.dof(links));
    let mut symbols = Symbols::new();
    let mut starts = [0; 8];
    for (start, category) in starts.iter_mut().zip(CATEGORIES) {
        let here = format!("{at}: symbols.{category}");
        let entry = object.get(category).ok_or_else(|| anyhow!("{at}: symbols: missing {category:?}"))?;
        let names: Vec<&Value> = match category {
            "gravity" => vec![entry],
            _ => {
                let len = match category {
                    "coordinates" | "rates" | "torques" => dof,
                    "pivot_acceleration" => kind.space(),
                    _ => n,
                };
                array(entry, len, &here)?.iter().collect()
            }
        };
        *start = symbols.len();
        for name in names {
            let name =
                name.as_str().ok_or_else(|| anyhow!("{here}: symbol names must be strings, got {name}"))?;
            symbols.add(name).with_context(|| here.clone())?;
        }
    }
    if let Some(extra) = object.keys().find(|k| !CATEGORIES.contains(&k.as_str())) {
        bail!("{at}: symbols: unknown category {extra:?}");
    }
    let [coordinates, rates, masses, lengths, gravity, damping, torques, pivot_acceleration] = starts;
    let layout = Layout {
        coordinates,
        rates,
        masses,
        lengths,
        gravity,
        damping,
        torques,
        pivot_acceleration,
        len: symbols.len(),
    };
    Ok((symbols, layout))
}

/// Loads every `*.json` case in `dir`: planar cases by `n`, then spatial by `n`.
///
/// Errors if `dir` cannot be read, holds no case, or holds two cases of the same kind
/// and `n`, or if any case fails to load.
pub fn load_all(dir: &Path) -> Result<Vec<Case>> {
    let entries = std::fs::read_dir(dir)
        .with_context(|| format!("{}: cannot read the reference cases", dir.display()))?;
    let mut cases = Vec::new();
    for entry in entries {
        let path = entry.with_context(|| format!("{}: cannot list", dir.display()))?.path();
        if path.extension().is_some_and(|e| e == "json") {
            cases.push(Case::load(&path)?);
        }
    }
    ensure!(
        !cases.is_empty(),
        "{}: no reference cases (*.json); generate them with `cargo xtask reference`",
        dir.display()
    );
    cases.sort_by_key(|c| (c.kind, c.links));
    for pair in cases.windows(2) {
        ensure!(
            (pair[0].kind, pair[0].links) != (pair[1].kind, pair[1].links),
            "{} and {} are both {} n={}",
            pair[0].path.display(),
            pair[1].path.display(),
            pair[0].kind,
            pair[0].links
        );
    }
    Ok(cases)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    /// The hand-derived single planar pendulum (test fixture `planar_n1.json`).
    fn fixtures() -> PathBuf {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests").join("fixtures")
    }

    fn planar_point(th: f64, dth: f64) -> (Params, Point) {
        let params = Params { masses: vec![2.0], lengths: vec![0.5], gravity: 9.81, damping: vec![0.3] };
        let point =
            Point { q: vec![th], qd: vec![dth], torque: vec![0.7], pivot_acceleration: vec![1.5, -2.0] };
        (params, point)
    }

    #[test]
    fn planar_fixture_evaluates_to_the_hand_derivation() {
        let case = Case::load(&fixtures().join("planar_n1.json")).unwrap();
        assert_eq!(
            (case.name.as_str(), case.kind, case.links, case.dof()),
            ("planar_n1", Kind::Planar, 1, 1)
        );
        let (p, x) = planar_point(0.4, -1.2);
        let e = case.evaluate(&p, &x);
        let (m, l, g) = (2.0, 0.5, 9.81);
        let (s, c) = 0.4f64.sin_cos();
        assert_eq!(e.mass_matrix[(0, 0)], m * l * l);
        assert_eq!(e.velocity_terms[0], 0.0);
        assert!((e.gravity_terms[0] - m * g * l * s).abs() < 1e-14);
        assert!((e.pivot_terms[0] - m * l * (1.5 * c - 2.0 * s)).abs() < 1e-14);
        assert!((e.generalized_forces[0] - (0.7 + 0.3 * 1.2)).abs() < 1e-14);
        assert!((e.kinetic_energy - 0.5 * m * l * l * 1.44).abs() < 1e-14);
        assert!((e.potential_energy + m * g * l * c).abs() < 1e-14);
        let a = case.accelerations(&p, &x);
        let expected = (0.7 + 0.3 * 1.2 - m * g * l * s - m * l * (1.5 * c - 2.0 * s)) / (m * l * l);
        assert!((a[0] - expected).abs() < 1e-13, "{a} vs {expected}");
        // Scales: Q = σ − λ θ̇ has scale |σ| + |λ θ̇|.
        let (values, s) = case.evaluate_with_scales(&p, &x);
        assert!((s.generalized_forces[0] - (0.7 + 0.36)).abs() < 1e-14);
        assert_eq!(values, e);
    }

    #[test]
    fn spatial_fixture_matches_the_spherical_pendulum() {
        // θ̈ = sinθ cosθ φ̇² − (g/l) sinθ,  φ̈ = −2 cotθ θ̇ φ̇ without torque, damping, drive.
        let case = Case::load(&fixtures().join("spatial_n1.json")).unwrap();
        assert_eq!((case.kind, case.dof()), (Kind::Spatial, 2));
        let params = Params { masses: vec![1.5], lengths: vec![0.8], gravity: 9.81, damping: vec![0.0] };
        let (th, ph, thd, phd) = (0.9, 2.0, 0.7, -1.3);
        let point = Point {
            q: vec![th, ph],
            qd: vec![thd, phd],
            torque: vec![0.0, 0.0],
            pivot_acceleration: vec![0.0, 0.0, 0.0],
        };
        let a = case.accelerations(&params, &point);
        let expected0 = th.sin() * th.cos() * phd * phd - 9.81 / 0.8 * th.sin();
        assert!((a[0] - expected0).abs() < 1e-13);
        assert!((a[1] + 2.0 * thd * phd / th.tan()).abs() < 1e-13);
    }

    #[test]
    #[should_panic(expected = "planar_n1: qd has 2 entries, expected 1")]
    fn wrong_point_length_panics_naming_the_vector() {
        let case = Case::load(&fixtures().join("planar_n1.json")).unwrap();
        let (p, mut x) = planar_point(0.1, 0.2);
        x.qd.push(0.0);
        case.evaluate(&p, &x);
    }

    /// Writes `value` (the planar fixture after `edit`) as `<name>.json` in a fresh
    /// directory and loads it.
    fn load_edited(name: &str, edit: impl FnOnce(&mut Value)) -> Result<Case> {
        let text = std::fs::read_to_string(fixtures().join("planar_n1.json")).unwrap();
        let mut value: Value = serde_json::from_str(&text).unwrap();
        edit(&mut value);
        let dir = std::env::temp_dir().join(format!("xtask-case-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(format!("{name}.json"));
        std::fs::write(&path, value.to_string()).unwrap();
        let result = Case::load(&path);
        std::fs::remove_dir_all(&dir).unwrap();
        result
    }

    fn load_error(edit: impl FnOnce(&mut Value)) -> String {
        format!("{:#}", load_edited("planar_n1", edit).unwrap_err())
    }

    #[test]
    fn validation_errors_name_file_case_and_entry() {
        type Edit = Box<dyn FnOnce(&mut Value)>;
        let cases: Vec<(Edit, &str)> = vec![
            (Box::new(|v| v["format"] = json!("pendulum-reference/9")), "format is \"pendulum-reference/9\""),
            (Box::new(|v| v["kind"] = json!("conical")), "case planar_n1: unknown kind \"conical\""),
            (Box::new(|v| v["links"] = json!(0)), "\"links\" must be a positive integer"),
            (Box::new(|v| v["links"] = json!(2)), "symbols.coordinates: has 1 entries, expected 2"),
            (
                Box::new(|v| drop(v.as_object_mut().unwrap().remove("gravity_terms"))),
                "missing key \"gravity_terms\"",
            ),
            (Box::new(|v| v["symbols"]["damping"] = json!([])), "symbols.damping: has 0 entries, expected 1"),
            (
                Box::new(|v| v["symbols"]["pivot_acceleration"] = json!(["ax"])),
                "pivot_acceleration: has 1 entries, expected 2",
            ),
            (
                Box::new(|v| v["symbols"]["torques"] = json!(["th1"])),
                "symbols.torques: symbol \"th1\" is listed twice",
            ),
            (
                Box::new(|v| v["symbols"]["gravity"] = json!(9)),
                "symbols.gravity: symbol names must be strings",
            ),
            (Box::new(|v| v["symbols"]["extra"] = json!([])), "symbols: unknown category \"extra\""),
            (
                Box::new(|v| v["mass_matrix"] = json!([1])),
                "case planar_n1: mass_matrix[0]: expected an array of 1 entries",
            ),
            (Box::new(|v| v["mass_matrix"] = json!([[1], [2]])), "mass_matrix: has 2 entries, expected 1"),
            (
                Box::new(|v| v["mass_matrix"][0][0] = json!(["*", "m1", "th9"])),
                "case planar_n1: mass_matrix[0][0]: unknown symbol \"th9\"",
            ),
            (
                Box::new(|v| v["pivot_terms"][0] = json!(["tan", "th1"])),
                "case planar_n1: pivot_terms[0]: unknown operator \"tan\"",
            ),
            (Box::new(|v| v["velocity_terms"] = json!([0, 0])), "velocity_terms: has 2 entries, expected 1"),
            (
                Box::new(|v| v["kinetic_energy"] = json!(["^", "m1", "l1"])),
                "kinetic_energy: \"^\" needs an integer exponent",
            ),
            (Box::new(|v| v["sympy_version"] = json!(1)), "\"sympy_version\" must be a string"),
            (
                Box::new(|v| v["equation"] = json!("mass_matrix * qdd = generalized_forces")),
                "case planar_n1: the equation is \"mass_matrix * qdd = generalized_forces\", expected",
            ),
        ];
        for (edit, expected) in cases {
            let message = load_error(edit);
            assert!(message.contains(expected), "expected {expected:?} in {message:?}");
            assert!(message.contains("planar_n1.json"), "{message}");
        }
        let message = format!("{:#}", load_edited("planar_n2", |_| ()).unwrap_err());
        assert!(message.contains("case planar_n1: the file is named \"planar_n2\""), "{message}");
    }

    #[test]
    fn load_all_sorts_and_rejects_empty_directories() {
        let cases = load_all(&fixtures()).unwrap();
        let names: Vec<_> = cases.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names, ["planar_n1", "planar_n2", "spatial_n1"]);
        let empty = std::env::temp_dir().join(format!("xtask-empty-{}", std::process::id()));
        std::fs::create_dir_all(&empty).unwrap();
        let message = load_all(&empty).unwrap_err().to_string();
        std::fs::remove_dir_all(&empty).unwrap();
        assert!(message.contains("no reference cases"), "{message}");
        assert!(load_all(&empty).unwrap_err().to_string().contains("cannot read"));
    }
}
