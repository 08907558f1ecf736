//! The claims-file parser (`xtask::claims::syntax::parse`) on arbitrary text: claims or
//! errors with positions inside the text, never a panic; every parsed entry, printed in
//! the file's syntax, parses again and prints the same (the corrected claims a
//! diagnosis prints are such printed entries).
#![no_main]

use libfuzzer_sys::fuzz_target;
use xtask::claims::syntax::parse;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    match parse(text) {
        Ok(claims) => {
            for claim in claims {
                let kind = if claim.chains.spatial { "spatial" } else { "planar" };
                for entry in &claim.entries {
                    let printed = entry.render();
                    let again = parse(&format!("claim \"x\"\nchain {kind}\n{printed}\n"))
                        .unwrap_or_else(|e| panic!("{printed:?} does not parse again: {e:?}"));
                    assert_eq!(again[0].entries[0].render(), printed);
                }
            }
        }
        Err(errors) => {
            let lines = text.lines().count().max(1);
            for e in errors {
                assert!(e.pos.line >= 1 && e.pos.line <= lines && e.pos.col >= 1, "{e:?}");
            }
        }
    }
});
