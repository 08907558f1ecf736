//! `pendulum view`: a page (and the live page's socket) served on localhost until Ctrl-C.

use std::sync::atomic::Ordering;
use std::time::Duration;

use axum::Router;

use crate::error::{CliError, CliResult};
use crate::interrupt::{INTERRUPTED, StopsItself};

/// Serves `app` at `http://127.0.0.1:PORT/` (any free port for 0) on one thread until
/// Ctrl-C. A port that cannot be listened on is a usage error naming it.
pub fn serve(app: Router, port: u16, what: &str) -> CliResult<()> {
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_io()
        .enable_time()
        .build()
        .map_err(|e| CliError::failed(format!("cannot start the server: {e}")))?;
    let _stops = StopsItself::enter();
    runtime.block_on(async move {
        let listener = tokio::net::TcpListener::bind(("127.0.0.1", port)).await.map_err(|e| {
            CliError::invalid(format!("--port {port}: cannot listen on 127.0.0.1:{port}: {e}"))
        })?;
        let address =
            listener.local_addr().map_err(|e| CliError::failed(format!("the server's address: {e}")))?;
        eprintln!("pendulum: {what} at http://{address}/ (Ctrl-C stops)");
        let stopped = async {
            while !INTERRUPTED.load(Ordering::SeqCst) {
                tokio::time::sleep(Duration::from_millis(100)).await;
            }
        };
        axum::serve(listener, app)
            .with_graceful_shutdown(stopped)
            .await
            .map_err(|e| CliError::failed(format!("the server stopped: {e}")))?;
        eprintln!("pendulum: stopped");
        Ok(())
    })
}
