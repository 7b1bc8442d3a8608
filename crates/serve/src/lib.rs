//! `chatter serve`: the shop-floor application. A local web server (axum on tokio) serves one
//! page whose screens follow the work at the machine, each over the library calls the
//! command-line program makes:
//!
//! 1. **Machine & tool**: a setup (machine, tool, holder and the cutting process: teeth, radial
//!    immersion, up or down milling, K_s and beta); a tap-test FRF (UFF 58, CSV, CutPro `.frf`,
//!    `.txt`) fitted by LSCF with its stabilization diagram and the overlay of measured and
//!    fitted |H| ([`chatter_frf::fit_modes`], as `chatter fit-frf`), or a model file.
//! 2. **Lobes**: the FDM lobe diagram (Ding et al. 2010) with the Type B offset boundaries of
//!    Schmitz (2023, seed 001, Eq. 1-2 and 10-11), hover for speed, depth and chatter frequency,
//!    click to propose a cut, and the highest-MRR cut at a risk
//!    ([`chatter_stability::recommend`], as `chatter recommend`).
//! 3. **Cut log**: cuts entered by hand, or recordings (WAV, MP3, CSV) judged by chatter
//!    detection ([`chatter_jobs::detect`], as `chatter detect`) with the spectrum and the
//!    chatter frequency; the user confirms or overrules each verdict.
//! 4. **Learn**: Bayesian updating from the cuts and poles ([`chatter_jobs::update`]) and the
//!    sim-to-real gap diagnosis ([`chatter_jobs::diagnose`]) as a background job with progress
//!    and cancel; its result in plain words.
//! 5. **Export**: the model, the observations and the learning result as files.
//!
//! Everything is kept in SQLite under the data folder ([`db`]; uploads in [`store`]); the
//! page, its script and style are embedded in the binary and load nothing from the network.
//! The server binds 127.0.0.1 by default; [`exposure_warning`] says what another address
//! exposes. Requests from other origins are refused ([`app`]).

#![cfg_attr(test, allow(clippy::unwrap_used))]

pub mod app;
pub mod db;
pub mod error;
pub mod example;
pub mod store;
pub mod work;

pub use app::{App, router};
pub use error::{Result, ServeError};

use std::net::{IpAddr, SocketAddr};
use std::path::PathBuf;

/// How `chatter serve` was asked to run.
#[derive(Debug, Clone)]
pub struct ServeOptions {
    /// Address to listen on; default 127.0.0.1.
    pub host: IpAddr,
    /// Port; 0 lets the system choose (the address is reported when listening).
    pub port: u16,
    /// The data folder (created if needed).
    pub data: PathBuf,
    /// Add the example setup (seed 001's mill with its cut log) if it is not there yet.
    pub example: bool,
}

impl ServeOptions {
    /// Options from the command line's text: `host` must be an IP address.
    pub fn new(host: &str, port: u16, data: PathBuf, example: bool) -> Result<Self> {
        let host = host.parse().map_err(|_| {
            ServeError::bad(
                "--host",
                format!("`{host}`: expected an IP address such as 127.0.0.1 or 0.0.0.0"),
            )
        })?;
        Ok(Self {
            host,
            port,
            data,
            example,
        })
    }
}

/// The warning a non-loopback address deserves, None for a loopback one.
///
/// ```
/// use chatter_serve::{ServeOptions, exposure_warning};
/// let everywhere = ServeOptions::new("0.0.0.0", 8080, "data".into(), false)?;
/// assert!(exposure_warning(everywhere.host).is_some_and(|w| w.contains("network")));
/// let local = ServeOptions::new("127.0.0.1", 8080, "data".into(), false)?;
/// assert!(exposure_warning(local.host).is_none());
/// // a host name is refused, naming the option
/// let e = ServeOptions::new("example.org", 8080, "data".into(), false).unwrap_err();
/// assert!(e.to_string().starts_with("--host"));
/// # Ok::<(), chatter_serve::ServeError>(())
/// ```
pub fn exposure_warning(host: IpAddr) -> Option<String> {
    (!host.is_loopback()).then(|| {
        format!(
            "listening on {host}: the setups, models, recordings and cut logs under the data \
             folder are then reachable by anyone on the network who can reach this machine, \
             without a password"
        )
    })
}

/// Open the data folder (seeding the example if asked), listen, report the address to
/// `listening` and serve until Ctrl-C.
pub fn serve(options: &ServeOptions, listening: impl FnOnce(SocketAddr)) -> Result<()> {
    let app = App::open(&options.data, options.host.is_loopback())?;
    if options.example {
        example::seed(&app)?;
    }
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
        .map_err(|e| ServeError::io(&options.data, e))?;
    runtime.block_on(async move {
        let address = SocketAddr::new(options.host, options.port);
        let listener = tokio::net::TcpListener::bind(address)
            .await
            .map_err(|e| ServeError::bad("--port", format!("cannot listen on {address}: {e}")))?;
        let bound = listener
            .local_addr()
            .map_err(|e| ServeError::bad("--port", e.to_string()))?;
        listening(bound);
        axum::serve(listener, router(app))
            .with_graceful_shutdown(async {
                let _ = tokio::signal::ctrl_c().await;
            })
            .await
            .map_err(|e| ServeError::bad("--port", e.to_string()))
    })
}
