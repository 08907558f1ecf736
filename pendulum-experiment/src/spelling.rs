//! Options named in messages, spelled by the front end that shows them: `--ramp-time` and
//! `--dim 3` on the command line, `ramp_time` and `dim=3` in Python.
//!
//! The experiment layer names every option it mentions through [`opt`] or [`opt_is`]. The
//! message keeps the option marked, and [`Front::spell`] writes it out for one front end.
//! An [`Error`](crate::Error)'s `Display` is the command line's; the Python layer asks for
//! its own with [`Error::message`](crate::Error::message).

use std::fmt::{self, Write};

/// Opens a marked option (a character of Unicode's private use area: never typed by a user).
const OPEN: char = '\u{E000}';
/// Separates a marked option's name from its value.
const VALUE: char = '\u{E001}';
/// Closes a marked option.
const CLOSE: char = '\u{E002}';

/// The option `name`, as the command line spells it without its dashes (`"ramp-time"`).
pub fn opt(name: &str) -> String {
    format!("{OPEN}{name}{CLOSE}")
}

/// The option `name` given `value` (`--dim 3`, `dim=3`).
pub fn opt_is(name: &str, value: impl fmt::Display) -> String {
    format!("{OPEN}{name}{VALUE}{value}{CLOSE}")
}

/// A front end, for the spelling of the options its messages name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Front {
    /// `pendulum`'s flags: `--ramp-time`, `--dim 3`.
    CommandLine,
    /// The Python package's keyword arguments: `ramp_time`, `dim=3`, `drive="circle"`.
    Python,
}

impl Front {
    /// `text` with every marked option written out for this front end.
    pub fn spell(self, text: &str) -> String {
        let mut out = String::with_capacity(text.len());
        let mut rest = text;
        while let Some(start) = rest.find(OPEN) {
            out.push_str(&rest[..start]);
            let marked = &rest[start + OPEN.len_utf8()..];
            let Some(end) = marked.find(CLOSE) else {
                // Not written by `opt`: kept as it is, without the mark.
                out.push_str(marked);
                return out;
            };
            let (name, value) = match marked[..end].split_once(VALUE) {
                Some((name, value)) => (name, Some(value)),
                None => (&marked[..end], None),
            };
            self.write(&mut out, name, value);
            rest = &marked[end + CLOSE.len_utf8()..];
        }
        out.push_str(rest);
        out
    }

    /// One option, `name` (the command line's, without dashes) and perhaps its value.
    fn write(self, out: &mut String, name: &str, value: Option<&str>) {
        // Writing to a `String` cannot fail.
        let _ = match (self, value) {
            (Self::CommandLine, None) => write!(out, "--{name}"),
            (Self::CommandLine, Some(value)) => write!(out, "--{name} {value}"),
            (Self::Python, None) => write!(out, "{}", python_name(name)),
            // A number as it is, anything else as a string.
            (Self::Python, Some(value)) if value.parse::<f64>().is_ok() => {
                write!(out, "{}={value}", python_name(name))
            }
            (Self::Python, Some(value)) => write!(out, "{}=\"{value}\"", python_name(name)),
        };
    }
}

/// The Python keyword argument of the command line's option `name`: its dashes made
/// underscores, and the few whose names differ.
fn python_name(name: &str) -> String {
    match name {
        // `pendulum.sweep`/`pendulum.atlas` take a list of kinds.
        "kind" => "kinds".into(),
        // `pendulum.Run.load(path)`.
        "from" => "path".into(),
        _ => name.replace('-', "_"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_front_end_spells_the_options_of_one_message_its_own_way() {
        let text = format!(
            "{} {} s must be shorter than {}; {} needs {}",
            opt("ramp-time"),
            5,
            opt_is("duration", 30),
            opt_is("drive", "circle"),
            opt_is("dim", 3)
        );
        assert_eq!(
            Front::CommandLine.spell(&text),
            "--ramp-time 5 s must be shorter than --duration 30; --drive circle needs --dim 3"
        );
        assert_eq!(
            Front::Python.spell(&text),
            "ramp_time 5 s must be shorter than duration=30; drive=\"circle\" needs dim=3"
        );
        assert_eq!(Front::Python.spell(&opt("kind")), "kinds");
        assert_eq!(Front::Python.spell("no options"), "no options");
        // A mark left open loses only its mark.
        assert_eq!(Front::CommandLine.spell("a \u{E000}b"), "a b");
    }
}
