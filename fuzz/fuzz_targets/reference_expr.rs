//! The reference-expression parser (`xtask::expr::Expr::parse`) on arbitrary JSON: an
//! expression tree or an error naming what is wrong, never a panic; a parsed tree
//! evaluates without panicking.
#![no_main]

use libfuzzer_sys::fuzz_target;
use xtask::expr::{Expr, Symbols};

fuzz_target!(|data: &[u8]| {
    let Ok(value) = serde_json::from_slice::<serde_json::Value>(data) else { return };
    let mut symbols = Symbols::new();
    for name in ["th1", "th2", "thd1", "m1", "l1", "g", "lam1", "sigma1", "ax", "ay"] {
        symbols.add(name).expect("distinct names");
    }
    match Expr::parse(&value, &symbols, "fuzz") {
        Ok(expr) => {
            let slots: Vec<f64> = (0..symbols.len()).map(|i| 0.1 + i as f64).collect();
            let _ = expr.eval(&slots);
            let _ = expr.eval_with_scale(&slots);
        }
        Err(e) => assert!(e.to_string().starts_with("fuzz: "), "{e}"),
    }
});
