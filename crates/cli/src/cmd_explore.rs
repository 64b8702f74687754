//! `facette explore`: the interactive BRDF explorer (crate `facette-explore`).

use anyhow::Result;
use clap::Args;
use facette_explore::{serve, ExploreOptions};
use std::io::Write;
use std::process::ExitCode;

#[derive(Args)]
pub struct ExploreArgs {
    /// Port to listen on (0: any free port; the URL printed says which).
    #[arg(long, default_value_t = 8470)]
    port: u16,
    /// Address to listen on. Without it the server binds to 127.0.0.1 and answers only this
    /// machine; with it (e.g. 0.0.0.0) anyone who can reach the address can use it.
    #[arg(long, value_name = "ADDRESS")]
    host: Option<String>,
    /// A material to open with, a TOML inline table (repeatable), e.g.
    /// '{type = "conductor", distribution = "ggx", alpha = 0.2, material = "Au"}'.
    #[arg(long, value_name = "TOML")]
    material: Vec<String>,
    /// A measured BRDF in the MERL binary format to open with (repeatable).
    #[arg(long, value_name = "FILE")]
    merl: Vec<std::path::PathBuf>,
}

pub fn run(a: ExploreArgs) -> Result<ExitCode> {
    if let Some(h) = &a.host {
        eprintln!(
            "warning: --host {h}: the explorer answers every client that reaches this address"
        );
    }
    let options = ExploreOptions {
        host: a.host,
        port: a.port,
        materials: a.material,
        merl: a.merl,
    };
    serve(
        options,
        |addr| {
            let shown = if addr.ip().is_unspecified() {
                format!("localhost:{}", addr.port())
            } else {
                addr.to_string()
            };
            println!("facette explore: listening on http://{shown}/ (Ctrl-C stops)");
            let _ = std::io::stdout().flush();
        },
        std::future::pending(),
    )?;
    Ok(ExitCode::SUCCESS)
}
