//! `pendulum view --live`: a chain simulated in real time on the server, one per page,
//! streamed over a WebSocket; the page steers the pivot and sets the drive and damping.

mod session;

use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use axum::Router;
use axum::extract::Path;
use axum::extract::ws::{Message, WebSocket, WebSocketUpgrade};
use axum::http::StatusCode;
use axum::response::{Html, IntoResponse};
use axum::routing::get;
use clap::Args;
use nalgebra::Dyn;
use pendulum_core::Chain;

use crate::args::ChainOptions;
use crate::chain_args::chain_of;
use crate::error::{CliError, CliResult};
use crate::interrupt::INTERRUPTED;
use session::{Control, STEP, Session};

/// The live page: HTML and style, with `/*DRAW*/` and `/*LIVE*/` where the scripts go.
const PAGE: &str = include_str!("live.html");
/// The live page's script.
const LIVE: &str = include_str!("live.js");
/// How far the simulation may fall behind the clock before it skips ahead (it then runs
/// slower than real time instead of catching up in a burst), s.
const MAX_LAG: f64 = 0.25;
/// The longest `/hold`, s.
const MAX_HOLD: f64 = 60.0;
/// Frames per second sent to the page.
const FPS: u64 = 60;

/// The chain and drive of `pendulum view --live` (defaults: the README's whirl).
#[derive(Debug, Args)]
pub struct LiveArgs {
    /// Simulate a chain in real time instead of showing a run: the page steers the pivot
    /// (drag the red square) and sets the circling speed, radius and damping.
    #[arg(long)]
    pub live: bool,
    /// --live: number of links.
    #[arg(long, default_value_t = 100, requires = "live")]
    pub n: usize,
    /// --live: masses, kg (one value, a comma list or a file).
    #[arg(long, default_value = "0.01", requires = "live", value_name = "VALUE|LIST|FILE")]
    pub masses: String,
    /// --live: rod lengths, m (one value, a comma list or a file).
    #[arg(long, default_value = "0.01", requires = "live", value_name = "VALUE|LIST|FILE")]
    pub lengths: String,
    /// --live: gravitational acceleration g, m/s² (along −z).
    #[arg(long, default_value_t = 9.81, requires = "live", allow_negative_numbers = true)]
    pub gravity: f64,
    /// --live: every link's damping λ at the start, N·m·s.
    #[arg(long, default_value_t = 3e-4, requires = "live", allow_negative_numbers = true)]
    pub damping: f64,
    /// --live: the radius of the pivot's circle at the start, m.
    #[arg(long, default_value_t = 0.02, requires = "live", allow_negative_numbers = true)]
    pub radius: f64,
    /// --live: the pivot's circling speed at the start, rad/s (reached in about 2 s).
    #[arg(long, default_value_t = 6.0, requires = "live", allow_negative_numbers = true)]
    pub omega: f64,
    /// --live: each page's chain begins this far into its motion (simulated at full
    /// speed before its first frame: past the spin-up, or into a settled whirl), s.
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 0.0,
        requires = "live",
        allow_negative_numbers = true
    )]
    pub start: f64,
}

/// The longest `--start`, s.
const MAX_START: f64 = 3600.0;

/// The chain and drive every page starts from.
#[derive(Debug, Clone)]
struct Start {
    chain: Chain<Dyn>,
    damping: f64,
    radius: f64,
    omega: f64,
    time: f64,
}

impl Start {
    /// A session at the start time.
    fn session(&self) -> Result<Session, String> {
        let mut session = Session::new(self.chain.clone(), self.damping, self.radius, self.omega)?;
        session.run_until(self.time)?;
        Ok(session)
    }
}

/// What the options describe, checked by making a session of it before serving (each
/// page gets its own).
fn start(args: &LiveArgs) -> CliResult<Start> {
    let options = ChainOptions {
        n: Some(args.n),
        masses: args.masses.clone(),
        lengths: args.lengths.clone(),
        gravity: args.gravity,
    };
    if !(0.0..=MAX_START).contains(&args.start) {
        return Err(CliError::invalid(format!("--start {}: must be a time in 0…{MAX_START} s", args.start)));
    }
    let chain = chain_of(&options)?;
    let (damping, radius, omega, time) = (args.damping, args.radius, args.omega, 0.0);
    let start = Start { chain, damping, radius, omega, time };
    start.session().map_err(|e| CliError::invalid(format!("--live: {e}")))?;
    Ok(Start { time: args.start, ..start })
}

/// Serves the live page on `port` until Ctrl-C.
pub fn live(args: &LiveArgs, port: u16) -> CliResult<()> {
    let start = start(args)?;
    let what = format!("live: {} links, a new chain for every page", start.chain.links());
    let page = PAGE.replacen("/*DRAW*/", pendulum_experiment::page::DRAW, 1).replacen("/*LIVE*/", LIVE, 1);
    let app = Router::new()
        .route("/", get(move || async move { Html(page) }))
        .route("/hold/{seconds}", get(hold))
        .route(
            "/socket",
            get(move |upgrade: WebSocketUpgrade| async move {
                // The run up to the start time, before the socket opens and off the server's
                // thread (it would hold up every other page).
                let ready = tokio::task::spawn_blocking(move || start.session()).await;
                match ready.unwrap_or_else(|e| Err(e.to_string())) {
                    Ok(session) => upgrade.on_upgrade(move |socket| stream(socket, session)).into_response(),
                    Err(error) => (StatusCode::INTERNAL_SERVER_ERROR, error).into_response(),
                }
            }),
        );
    super::serve::serve(app, port, &what)
}

/// `GET /hold/S` answers after `S` seconds (at most [`MAX_HOLD`]): a page opened as
/// `#hold=S` asks it, and a headless browser's virtual time (`--virtual-time-budget`,
/// which does not wait for a WebSocket) waits for the request, so its screenshot shows
/// the chain S seconds on.
async fn hold(Path(seconds): Path<f64>) -> Result<&'static str, StatusCode> {
    if !(0.0..=MAX_HOLD).contains(&seconds) {
        return Err(StatusCode::BAD_REQUEST);
    }
    tokio::time::sleep(Duration::from_secs_f64(seconds)).await;
    Ok("held")
}

/// One page's chain: steps to the clock every 1/FPS s, sends the frame, applies what
/// the page asks. Ends when the page goes (the server goes on).
async fn stream(mut socket: WebSocket, mut session: Session) {
    let mut ticks = tokio::time::interval(Duration::from_micros(1_000_000 / FPS));
    ticks.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Skip);
    let begun = Instant::now();
    // The simulated time is the time since the page came, plus the start, less what was
    // skipped when the simulation fell behind.
    let (mut skipped, mut busy, mut window, mut load) = (-session.t(), Duration::ZERO, Instant::now(), None);
    loop {
        tokio::select! {
            message = socket.recv() => {
                let text = match message {
                    Some(Ok(Message::Text(text))) => text,
                    Some(Ok(Message::Close(_))) | None | Some(Err(_)) => return,
                    Some(Ok(_)) => continue,
                };
                let reply = match serde_json::from_str::<Control>(&text) {
                    Ok(Control::Selftest(result)) => {
                        eprintln!("pendulum: live page self-test: {result}");
                        continue;
                    }
                    Ok(control) => session.apply(control),
                    Err(e) => Err(format!("not a control ({e}): {}", text.chars().take(80).collect::<String>())),
                };
                if let Err(error) = reply {
                    let error = serde_json::json!({ "error": error }).to_string();
                    if socket.send(Message::Text(error.into())).await.is_err() {
                        return;
                    }
                }
            }
            _ = ticks.tick() => {
                if INTERRUPTED.load(Ordering::SeqCst) {
                    let _ = socket.send(Message::Close(None)).await;
                    return;
                }
                let working = Instant::now();
                let mut clock = begun.elapsed().as_secs_f64() - skipped;
                if clock - session.t() > MAX_LAG {
                    skipped += clock - session.t() - STEP;
                    clock = session.t() + STEP;
                }
                let error = session.run_until(clock).err();
                busy += working.elapsed();
                if window.elapsed() >= Duration::from_secs(1) {
                    load = Some(busy.as_secs_f64() / window.elapsed().as_secs_f64());
                    (busy, window) = (Duration::ZERO, Instant::now());
                }
                let frame = serde_json::to_string(&session.frame(load, error)).unwrap_or_default();
                if socket.send(Message::Text(frame.into())).await.is_err() {
                    return;
                }
            }
        }
    }
}
