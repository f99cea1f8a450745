//! `alba run`: the command line of the application layer (alba-app), with
//! Ctrl-C and SIGTERM as its shutdown signal.

use alba_diag::render_all;
use std::path::Path;
use std::process::ExitCode;

pub fn run(dir: &Path, opts: alba_app::Options, banner: Option<&str>) -> ExitCode {
    let rt = match tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
    {
        Ok(rt) => rt,
        Err(e) => {
            eprintln!("error: cannot start: {e}");
            return ExitCode::FAILURE;
        }
    };
    let tls = opts.tls;
    let banner = banner.map(str::to_string);
    let result = rt.block_on(alba_app::run(
        dir,
        opts,
        |local| {
            if let Some(b) = banner {
                println!("{b}");
            }
            let scheme = alba_app::tls::scheme(dir, tls, local);
            println!(
                "Alba studio: {scheme}://{local}/  (project {}; Ctrl-C stops)",
                dir.display()
            );
        },
        shutdown_signal(),
    ));
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(alba_app::RunError::Compile(c)) => {
            eprint!("{}", render_all(&c.diagnostics, &c.project.files));
            ExitCode::FAILURE
        }
        Err(alba_app::RunError::Other(m)) => {
            eprintln!("error: {m}");
            ExitCode::FAILURE
        }
    }
}

/// Ctrl-C or SIGTERM.
pub(crate) async fn shutdown_signal() {
    let ctrl_c = async {
        let _ = tokio::signal::ctrl_c().await;
    };
    #[cfg(unix)]
    let term = async {
        match tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate()) {
            Ok(mut s) => {
                s.recv().await;
            }
            Err(_) => std::future::pending::<()>().await,
        }
    };
    #[cfg(not(unix))]
    let term = std::future::pending::<()>();
    tokio::select! {
        () = ctrl_c => {},
        () = term => {},
    }
}
