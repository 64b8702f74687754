//! The HTTP server: static assets, the schema, and one POST route per view. Requests are
//! evaluated on blocking threads (the computation itself is parallel, on rayon's pool);
//! a request the app abandons is cancelled. By default the server binds to 127.0.0.1 and
//! refuses any request that is not from the loopback interface or whose `Host` is not a
//! loopback name (a web page elsewhere cannot reach it by DNS rebinding); `--host` lifts
//! both. It writes no files.

use crate::assets::asset;
use crate::cancel::Cancel;
use crate::fitting::FitRequest;
use crate::frame::Frame;
use crate::material::{Material, MaterialCache};
use crate::patch_ndf::PatchNdfRequest;
use crate::preview::{PreviewRequest, PreviewScenes};
use crate::schema_json::schema_json;
use crate::validation::ValidateRequest;
use crate::views::{self, AlbedoRequest, HemisphereRequest, SliceRequest};
use anyhow::{Context, Result};
use axum::body::Body;
use axum::extract::{ConnectInfo, DefaultBodyLimit, Request, State};
use axum::http::{header, HeaderMap, StatusCode, Uri};
use axum::middleware::{self, Next};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::{Json, Router};
use facette_lab::merl::MerlBrdf;
use serde::Deserialize;
use serde_json::json;
use std::net::SocketAddr;
use std::sync::Arc;
use std::time::Instant;

/// What `facette explore` was asked for.
#[derive(Clone, Debug, Default)]
pub struct ExploreOptions {
    /// Address to bind; `None`: 127.0.0.1, loopback requests only.
    pub host: Option<String>,
    /// 0: any free port.
    pub port: u16,
    /// Materials the app opens with (TOML inline tables).
    pub materials: Vec<String>,
    /// Measured BRDFs (MERL binary files) the app opens with.
    pub merl: Vec<std::path::PathBuf>,
}

struct AppState {
    cache: MaterialCache,
    previews: PreviewScenes,
    initial: Vec<String>,
    /// One permit per core: a computation waits for one before it starts, so a request
    /// the app abandons while it waits (a slider dragged on) never runs.
    workers: tokio::sync::Semaphore,
    /// Raised at shutdown: running computations stop at their next poll.
    stopping: Cancel,
}

type Shared = Arc<AppState>;

/// What the app opens with when no `--material` is given: a rough gold and an interfaced
/// Lambertian plastic in IL18's closed form (both deterministic and fast to evaluate).
pub const DEFAULT_MATERIALS: &[&str] = &[
    r#"{type = "conductor", distribution = "ggx", alpha = 0.2, material = "Au"}"#,
    r#"{type = "il", kd = [0.6, 0.25, 0.1], ni = 1.5, distribution = "beckmann", alpha = 0.3, evaluation = "approx"}"#,
];

/// Builds the initial materials (an error names the bad one), binds, calls `on_ready` with
/// the address, and serves until Ctrl-C (or `shutdown` resolves).
pub fn serve(
    options: ExploreOptions,
    on_ready: impl FnOnce(SocketAddr) + Send,
    shutdown: impl std::future::Future<Output = ()> + Send + 'static,
) -> Result<()> {
    let mut initial = Vec::new();
    let defaults: Vec<String> = DEFAULT_MATERIALS.iter().map(|s| s.to_string()).collect();
    let given = if options.materials.is_empty() {
        &defaults
    } else {
        &options.materials
    };
    for m in given {
        let built =
            crate::material::build(m).map_err(|e| anyhow::anyhow!("--material `{m}`: {e}"))?;
        initial.push(built.text);
    }
    let cache = MaterialCache::default();
    if options.merl.len() > MaterialCache::MEASURED_FILES {
        anyhow::bail!(
            "--merl: at most {} files (each is 35 MB in memory), got {}",
            MaterialCache::MEASURED_FILES,
            options.merl.len()
        );
    }
    for path in &options.merl {
        let merl = MerlBrdf::load(path).map_err(|e| anyhow::anyhow!("--merl: {e}"))?;
        let name = path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        initial.push(cache.add_measured(&name, merl).text());
    }
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .context("starting the server's runtime")?;
    let done = runtime.block_on(async move {
        let host = options.host.clone().unwrap_or_else(|| "127.0.0.1".into());
        let listener = tokio::net::TcpListener::bind((host.as_str(), options.port))
            .await
            .with_context(|| {
                format!(
                    "cannot listen on {host}:{} (another program on that port? `--port 0` picks a free one)",
                    options.port
                )
            })?;
        let addr = listener.local_addr()?;
        on_ready(addr);
        let workers = std::thread::available_parallelism().map_or(2, |n| n.get());
        let state = Arc::new(AppState {
            cache,
            previews: PreviewScenes::default(),
            initial,
            workers: tokio::sync::Semaphore::new(workers),
            stopping: Cancel::default(),
        });
        // Bound to a loopback address (the default, or `--host localhost`), the server
        // answers loopback requests naming a loopback host only.
        let app = router(state.clone(), addr.ip().is_loopback());
        let stop = Arc::new(tokio::sync::Notify::new());
        let signal = stop.clone();
        tokio::spawn(async move {
            tokio::select! {
                _ = tokio::signal::ctrl_c() => {}
                _ = shutdown => {}
            }
            state.stopping.cancel();
            signal.notify_waiters();
        });
        let graceful = stop.clone();
        let serving = axum::serve(
            listener,
            app.into_make_service_with_connect_info::<SocketAddr>(),
        )
        .with_graceful_shutdown(async move { graceful.notified().await });
        // Requests still running get two seconds after the signal, then the server stops.
        tokio::select! {
            r = serving => r.context("serving"),
            _ = async {
                stop.notified().await;
                tokio::time::sleep(std::time::Duration::from_secs(2)).await;
            } => Ok(()),
        }
    });
    done?;
    // Blocking work still running (a fit cannot be interrupted) is left to end with the
    // process rather than waited for.
    runtime.shutdown_timeout(std::time::Duration::from_millis(200));
    Ok(())
}

fn router(state: Shared, local_only: bool) -> Router {
    let app = Router::new()
        .route("/api/schema", get(|| async { Json(schema_json()) }))
        .route("/api/initial", get(initial))
        .route("/api/material", post(material))
        .route("/api/slice", post(slice))
        .route("/api/hemisphere", post(hemisphere))
        .route("/api/albedo", post(albedo))
        .route("/api/validate", post(validate))
        .route("/api/preview", post(preview))
        .route("/api/patch-ndf", post(patch_ndf))
        .route("/api/fit", post(fit))
        .route(
            "/api/measured",
            post(measured).layer(DefaultBodyLimit::max(MEASURED_BODY_LIMIT)),
        )
        .fallback(get(static_asset))
        .with_state(state);
    if local_only {
        app.layer(middleware::from_fn(loopback_only))
    } else {
        app
    }
}

/// Whether a `Host` header names this machine (`localhost`, `127.0.0.1`, `[::1]`, with
/// any port).
pub fn is_loopback_host(host: &str) -> bool {
    let name = match host.strip_prefix('[') {
        Some(v6) => v6.split(']').next().unwrap_or(""),
        None => host.rsplit_once(':').map_or(host, |(h, _)| h),
    };
    name.eq_ignore_ascii_case("localhost")
        || name
            .parse::<std::net::IpAddr>()
            .is_ok_and(|ip| ip.is_loopback())
}

async fn loopback_only(
    ConnectInfo(peer): ConnectInfo<SocketAddr>,
    request: Request,
    next: Next,
) -> Response {
    let host_ok = request
        .headers()
        .get(header::HOST)
        .and_then(|h| h.to_str().ok())
        .is_some_and(is_loopback_host);
    if !peer.ip().is_loopback() || !host_ok {
        return (
            StatusCode::FORBIDDEN,
            "facette explore answers this machine only (start it with --host to serve others)\n",
        )
            .into_response();
    }
    next.run(request).await
}

async fn static_asset(uri: Uri) -> Response {
    if uri.path() == "/favicon.ico" {
        return StatusCode::NO_CONTENT.into_response();
    }
    match asset(uri.path()) {
        Some((ty, body)) => ([(header::CONTENT_TYPE, ty)], body).into_response(),
        None => (StatusCode::NOT_FOUND, format!("no {}\n", uri.path())).into_response(),
    }
}

/// Materials and measured files the app opens with: `{"materials": [text…], "measured":
/// [{id, name, text, valid_bins}…]}` (a measured file's text is `measured:ID`).
async fn initial(State(s): State<Shared>) -> Json<serde_json::Value> {
    let (materials, measured): (Vec<&String>, Vec<&String>) = s
        .initial
        .iter()
        .partition(|t| !t.starts_with(crate::material::MEASURED_PREFIX));
    let measured: Vec<_> = measured
        .iter()
        .filter_map(|t| t[crate::material::MEASURED_PREFIX.len()..].parse().ok())
        .filter_map(|id| s.cache.measured(id).ok())
        .map(|f| json!({"id": f.id, "name": f.name, "text": f.text(), "valid_bins": f.valid_bins}))
        .collect();
    Json(json!({ "materials": materials, "measured": measured }))
}

/// The largest upload: a MERL file is 34,992,016 bytes.
const MEASURED_BODY_LIMIT: usize = 40 << 20;

fn error(status: StatusCode, message: impl Into<String>) -> Response {
    (status, Json(json!({ "error": message.into() }))).into_response()
}

#[derive(Deserialize)]
struct MaterialRequest {
    material: String,
}

/// Answers a request whose fields passed `check` (a 400 with its message otherwise) by
/// running `work` on a blocking thread, with the server's state, once one of the state's
/// worker permits is free, with a flag raised if the request is dropped, and answers its
/// value with `respond`; `None` (cancelled, or the server stopping) is a 503, an error a 422
/// with its message, a panic a 500 (the server goes on).
async fn blocking<T: Send + 'static>(
    s: &Shared,
    check: Result<(), String>,
    work: impl FnOnce(&Shared, &Cancel) -> Result<Option<T>, String> + Send + 'static,
    respond: impl FnOnce(T) -> Response,
) -> Response {
    if let Err(e) = check {
        return error(StatusCode::BAD_REQUEST, e);
    }
    let Ok(_permit) = s.workers.acquire().await else {
        return error(StatusCode::SERVICE_UNAVAILABLE, "the server is stopping");
    };
    let cancel = Cancel::default();
    let guard = cancel.guard();
    let state = s.clone();
    let done = tokio::task::spawn_blocking(move || {
        if state.stopping.is_cancelled() || cancel.is_cancelled() {
            return Ok(None);
        }
        work(&state, &cancel)
    })
    .await;
    guard.disarm();
    match done {
        Ok(Ok(Some(v))) => respond(v),
        Ok(Ok(None)) => error(StatusCode::SERVICE_UNAVAILABLE, "cancelled"),
        Ok(Err(e)) => error(StatusCode::UNPROCESSABLE_ENTITY, e),
        Err(e) => error(
            StatusCode::INTERNAL_SERVER_ERROR,
            format!("internal error while evaluating: {e}"),
        ),
    }
}

fn frame_response(frame: Frame) -> Response {
    Response::builder()
        .header(header::CONTENT_TYPE, "application/octet-stream")
        .body(Body::from(frame.encode()))
        .unwrap_or_else(|e| error(StatusCode::INTERNAL_SERVER_ERROR, e.to_string()))
}

/// Loads an uploaded MERL file (the body; its name in `x-file-name`) into memory; nothing
/// is written to disk. A corrupt file is a 422 with the reader's message.
async fn measured(
    State(s): State<Shared>,
    headers: HeaderMap,
    body: axum::body::Bytes,
) -> Response {
    // The name is required: a page elsewhere cannot send this header without a preflight
    // the server does not answer. The app percent-encodes it (headers are bytes).
    let Some(name) = headers
        .get("x-file-name")
        .and_then(|h| h.to_str().ok())
        .map(|h| {
            percent_encoding::percent_decode_str(h)
                .decode_utf8_lossy()
                .into_owned()
        })
    else {
        return error(
            StatusCode::BAD_REQUEST,
            "an upload names its file in `x-file-name`",
        );
    };
    blocking(
        &s,
        Ok(()),
        move |state, _| {
            let merl = MerlBrdf::from_bytes(&body, &name).map_err(|e| e.to_string())?;
            Ok(Some(state.cache.add_measured(&name, merl)))
        },
        |f| {
            Json(json!({"id": f.id, "name": f.name, "text": f.text(), "valid_bins": f.valid_bins}))
                .into_response()
        },
    )
    .await
}

/// Parses and builds a material: its canonical text, its table and what it is, or the
/// grammar's error.
async fn material(State(s): State<Shared>, Json(q): Json<MaterialRequest>) -> Response {
    blocking(
        &s,
        Ok(()),
        move |state, _| state.cache.get(&q.material).map(Some),
        |m| {
            Json(json!({
                "text": m.text,
                "table": m.table,
                "describe": m.bsdf.describe(),
                "stochastic": !m.bsdf.eval_is_deterministic(),
            }))
            .into_response()
        },
    )
    .await
}

/// A view of one material: checked, built (the grammar's error otherwise), computed, and
/// answered as a frame with the computation's time in `compute_ms`.
async fn run_view(
    s: Shared,
    text: String,
    check: Result<(), String>,
    view: impl FnOnce(&Material, &Cancel) -> Option<Frame> + Send + 'static,
) -> Response {
    blocking(
        &s,
        check,
        move |state, cancel| {
            let m = state.cache.get(&text)?;
            let start = Instant::now();
            Ok(
                view(&m, cancel)
                    .map(|f| f.field("compute_ms", start.elapsed().as_secs_f64() * 1e3)),
            )
        },
        frame_response,
    )
    .await
}

async fn slice(State(s): State<Shared>, Json(q): Json<SliceRequest>) -> Response {
    run_view(s, q.material.clone(), q.check(), move |m, c| {
        views::slice(&*m.bsdf, &m.text, &q, c)
    })
    .await
}

async fn hemisphere(State(s): State<Shared>, Json(q): Json<HemisphereRequest>) -> Response {
    run_view(s, q.material.clone(), q.check(), move |m, c| {
        views::hemisphere(&*m.bsdf, &m.text, &q, c)
    })
    .await
}

async fn albedo(State(s): State<Shared>, Json(q): Json<AlbedoRequest>) -> Response {
    run_view(s, q.material.clone(), q.check(), move |m, c| {
        views::albedo(&*m.bsdf, &m.text, &q, c)
    })
    .await
}

async fn validate(State(s): State<Shared>, Json(q): Json<ValidateRequest>) -> Response {
    blocking(
        &s,
        q.check(),
        move |state, c| {
            let m = state.cache.get(&q.material)?;
            Ok(crate::validation::validate(&*m.bsdf, &q, c))
        },
        |v| Json(v).into_response(),
    )
    .await
}

async fn preview(State(s): State<Shared>, Json(q): Json<PreviewRequest>) -> Response {
    blocking(
        &s,
        q.check(),
        move |state, c| {
            // The material passes the grammar (and its cache) before the scene is built:
            // the scene loader takes more than a material (image textures, files).
            let m = state.cache.get(&q.material)?;
            let scene = state.previews.get(&m.text, q.width, q.height)?;
            crate::preview::render_pass(&scene, &q, c)
        },
        frame_response,
    )
    .await
}

async fn patch_ndf(State(s): State<Shared>, Json(q): Json<PatchNdfRequest>) -> Response {
    blocking(
        &s,
        q.check(),
        move |_, _| crate::patch_ndf::patch_ndf(&q).map(Some),
        frame_response,
    )
    .await
}

async fn fit(State(s): State<Shared>, Json(q): Json<FitRequest>) -> Response {
    blocking(
        &s,
        q.check(),
        move |state, _| {
            let f = state.cache.measured(q.measured)?;
            crate::fitting::fit(&f.merl, &q).map(|frame| Some(frame.field("measured_name", f.name)))
        },
        frame_response,
    )
    .await
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn loopback_hosts() {
        for h in [
            "localhost",
            "localhost:8470",
            "127.0.0.1:1",
            "[::1]:80",
            "127.0.0.2",
        ] {
            assert!(is_loopback_host(h), "{h}");
        }
        for h in [
            "example.com",
            "evil.localhost.example:80",
            "10.0.0.1:8470",
            "[2001:db8::1]:80",
        ] {
            assert!(!is_loopback_host(h), "{h}");
        }
    }
}
