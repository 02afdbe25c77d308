//! Citygen's interactive editor in the browser (Kelly 2008, §5): a local HTTP server over
//! an editable city and a page with a 2-D plan view where editing happens, a 3-D WebGL
//! view, Kelly's view / node / road / cell edit modes, the red-proposed / green-corrected
//! preview of Fig. 69, undo / redo, an output log and export buttons.
//!
//! ```text
//! cargo run --release --example editor -- [--preset citygen] [--port 8421] [--bind ADDR]
//! ```
//!
//! The server binds to 127.0.0.1 unless `--bind` says otherwise, generates the city,
//! prints the URL and serves until stopped (Ctrl+C).
//!
//! | file | what |
//! |---|---|
//! | `main.rs` | the command line |
//! | `http.rs` | sockets (tiny_http), body size limit, worker threads |
//! | `api.rs` | routes, request validation, status codes, the page's files |
//! | `session.rs` | the editable city behind the API: actions → edits, change events → deltas |
//! | `wire.rs` | what travels to the page: nodes, roads, cells with their content |
//! | `static/` | the page: plain JavaScript and WebGL |
//! | `e2e/` | the end-to-end test in headless Chromium (`.ci/browser.sh`) |

mod api;
mod http;
mod session;
mod wire;

#[cfg(test)]
mod tests;

use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::sync::Arc;

use clap::Parser;

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// The default port.
const DEFAULT_PORT: u16 = 8421;

/// Citygen's editor in the browser: serves the page and the editable city.
#[derive(Debug, Parser)]
#[command(version, about)]
struct Args {
    /// A built-in preset in the Citygen road mode (citygen, suburbia, milan) or a
    /// configuration file (….json).
    #[arg(long, default_value = "citygen")]
    preset: String,
    /// The city's side, metres (overrides the preset's).
    #[arg(long, value_parser = clap::value_parser!(u32).range(100..=100_000))]
    size: Option<u32>,
    /// The city seed (overrides the preset's).
    #[arg(long)]
    seed: Option<u64>,
    /// Start from an empty primary network (draw the city from scratch).
    #[arg(long)]
    empty: bool,
    /// The TCP port; 0 lets the system choose.
    #[arg(long, default_value_t = DEFAULT_PORT)]
    port: u16,
    /// The address to listen on. Default: 127.0.0.1 (this machine only); anything else
    /// exposes the editor to the network.
    #[arg(long, default_value_t = IpAddr::V4(Ipv4Addr::LOCALHOST))]
    bind: IpAddr,
}

fn main() {
    let args = Args::parse();
    if let Err(e) = run(&args) {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run(args: &Args) -> Result<(), String> {
    let started = std::time::Instant::now();
    let mut config = if args.preset.ends_with(".json") {
        polis::CityConfig::from_path(&args.preset).map_err(|e| e.to_string())?
    } else {
        polis::CityConfig::preset(&args.preset).map_err(|e| e.to_string())?
    };
    if let Some(size) = args.size {
        config.size_m = f64::from(size);
    }
    if let Some(seed) = args.seed {
        config.seed = seed;
    }
    let session = session::Session::new(config, args.empty).map_err(|e| e.to_string())?;
    eprintln!(
        "generated {} in {:.2} s",
        session.summary(),
        started.elapsed().as_secs_f64()
    );
    if !args.bind.is_loopback() {
        eprintln!(
            "warning: listening on {} exposes the editor to other machines",
            args.bind
        );
    }
    let api = Arc::new(api::Api::new(session));
    let running = http::serve(api, SocketAddr::new(args.bind, args.port))?;
    // The URL on its own line on standard output, for scripts (the browser test reads it).
    println!("http://{}/", running.addr);
    running.wait();
    Ok(())
}
