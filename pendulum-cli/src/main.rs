//! `pendulum`: simulate N-link pendulums and write what a person wants to look at
//! (trajectory and energy CSVs, run.json, an energy plot and an animation), evaluate
//! a model's terms as JSON, or find the normal modes and steady rotations of a chain.

mod args;
mod atlas;
mod chain_args;
mod cli;
mod error;
mod eval;
mod interrupt;
mod linearize;
mod modes;
mod plot;
mod render;
mod request;
mod simulate;
mod spec;
mod steady;
mod sweep;
mod view;
mod whirl;

use std::process::ExitCode;

use clap::Parser;
use clap::error::{ContextKind, ContextValue, ErrorKind};

use cli::{Cli, Command};

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => match e.kind() {
            ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => e.exit(),
            ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
                let _ = e.print();
                return ExitCode::from(2);
            }
            ErrorKind::ArgumentConflict => {
                let given: Vec<String> = std::env::args().skip(1).collect();
                eprintln!("{}", conflict(&e, &given).unwrap_or_else(|| one_line(&e.to_string())));
                return ExitCode::from(2);
            }
            _ => {
                eprintln!("{}", one_line(&e.to_string()));
                return ExitCode::from(2);
            }
        },
    };
    interrupt::install_handler();
    if !matches!(cli.command, Command::View(_)) {
        interrupt::quiet_on_broken_pipe();
    }
    let result = match &cli.command {
        Command::Simulate(args) => {
            // `pendulum simulate` alone: the demo.
            let demo = std::env::args_os().len() == 2;
            simulate::simulate(args, demo)
        }
        Command::Eval(args) => eval::eval(args),
        Command::Linearize(args) => linearize::run(args),
        Command::Modes(args) => modes::modes(args),
        Command::Steady(args) => steady::steady(args),
        Command::Render(args) => render::render(args),
        Command::View(args) => view::view(args),
        Command::Sweep(args) => sweep::sweep(args),
        Command::Atlas(args) => atlas::atlas(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            error::exit_code(&e)
        }
    }
}

/// clap's message on one line: the lines before its usage block, joined.
fn one_line(text: &str) -> String {
    let lines: Vec<&str> = text
        .lines()
        .take_while(|l| !l.starts_with("Usage:") && !l.starts_with("For more information"))
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect();
    if lines.is_empty() { "error: invalid arguments".into() } else { lines.join(" ") }
}

/// A conflict between options named by the ones given, not by every option of the group
/// clap lists (`--from X --n 5` named some 25): `None` when clap's error does not say.
fn conflict(e: &clap::Error, given: &[String]) -> Option<String> {
    let Some(ContextValue::String(arg)) = e.get(ContextKind::InvalidArg) else { return None };
    let others = match e.get(ContextKind::PriorArg)? {
        ContextValue::Strings(list) => list.clone(),
        ContextValue::String(one) => vec![one.clone()],
        _ => return None,
    };
    let flag = |usage: &str| usage.split([' ', '=']).next().unwrap_or_default().to_string();
    let given: Vec<String> = given.iter().map(|a| flag(a)).collect();
    let named: Vec<String> = others.into_iter().filter(|o| given.contains(&flag(o))).collect();
    (!named.is_empty())
        .then(|| format!("error: the argument '{arg}' cannot be used with {}", named.join(", ")))
}
