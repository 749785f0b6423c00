//! `skeletonise` command line: parses arguments, sets up logging, maps errors
//! to exit codes (0 ok, 1 runtime failure, 2 usage, 65 rejected features under
//! `on_error: fail`, 78 invalid pipeline file).

use clap::{Parser, Subcommand, ValueEnum};
use skeletonise::config;
use skeletonise::pipeline::{self, RunError, RunOptions};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;

/// mimalloc: the workers allocate and free many small graphs and vectors
/// per polygon, which the system allocator serves more slowly.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// Turns transparent huge pages off for this process (Linux).
///
/// mimalloc asks the kernel for huge pages on its arenas
/// (`madvise(MADV_HUGEPAGE)`), so the first touch of any part of 2 MiB
/// zeroes all of it. On the 1 000 000-vertex rough polygon through MA that
/// took 5.9–7.3 s of system time and the run 20.9–21.8 s; with 4 KiB pages
/// 1.6–1.8 s and 17.1–17.5 s, for 2 % more user time. Elsewhere it is
/// about even (0.96–1.03× on the rough polygon at 100 000 and 200 000
/// vertices, the rasterised Lena and the GSHHG lakes; BENCHMARKS.md).
/// `MIMALLOC_ALLOW_THP=0` does the same from outside. A kernel without
/// the setting changes nothing but speed.
fn no_huge_pages() {
    #[cfg(target_os = "linux")]
    // SAFETY: `prctl(PR_SET_THP_DISABLE, 1, 0, 0, 0)` only sets a flag of
    // the calling process; it reads and writes none of our memory.
    unsafe {
        libc::prctl(libc::PR_SET_THP_DISABLE, 1, 0, 0, 0);
    }
}

/// mimalloc's option `purge_delay` (its index in mimalloc 3's
/// `mi_option_e`: libmimalloc-sys 0.1.49 names only some of them).
const MI_OPTION_PURGE_DELAY: libmimalloc_sys::mi_option_t = 15;

/// mimalloc 3's default `purge_delay` (ms), by which [`prompt_purge`]
/// recognises the option.
const MI_DEFAULT_PURGE_DELAY: std::ffi::c_long = 1000;

/// Freed memory goes back to the system after 100 ms, not mimalloc 3's
/// 1 s: a huge polygon frees its Voronoi diagram's builder (hundreds of
/// MB) and at once makes the skeleton's graph, and with memory kept for a
/// second both were resident. Paired against the default (BENCHMARKS.md):
/// the rough 1 000 000-vertex polygon through MA peaks at 1 152 MiB instead
/// of 1 456 MiB (wall 1.03×), the rough 200 000-vertex one with every
/// method at 523 instead of 627 MiB (1.03×); 20 000 small islands take the
/// same time (0.99×; purging at once, 0 ms, cost them 4 %).
/// `MIMALLOC_PURGE_DELAY` in the environment is left to win, and nothing is
/// changed unless the option at that index holds mimalloc 3's default.
fn prompt_purge() {
    if std::env::var_os("MIMALLOC_PURGE_DELAY").is_some() {
        return;
    }
    // SAFETY: mimalloc's option calls read and write its own option table
    // (atomics); an index it knows is all they need.
    unsafe {
        if libmimalloc_sys::mi_option_get(MI_OPTION_PURGE_DELAY) == MI_DEFAULT_PURGE_DELAY {
            libmimalloc_sys::mi_option_set(MI_OPTION_PURGE_DELAY, 100);
        }
    }
}

const EXIT_RUNTIME: u8 = 1;
const EXIT_USAGE: u8 = 2;
const EXIT_REJECTED: u8 = 65;
const EXIT_CONFIG: u8 = 78;

#[derive(Parser)]
#[command(
    name = "skeletonise",
    version,
    about = "Collapse polygons to skeletons (VD, DVD, CDT, StSk, MA) and score them with the paper's deviation and distortion metrics"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Log format: `text` for people, `json` for scheduled jobs.
    #[arg(long, value_enum, default_value_t = LogFormat::Text, global = true)]
    log_format: LogFormat,
    /// Only warnings and errors.
    #[arg(short, long, global = true, conflicts_with = "verbose")]
    quiet: bool,
    /// More detail (-v debug, -vv trace).
    #[arg(short, long, action = clap::ArgAction::Count, global = true)]
    verbose: u8,
}

#[derive(Clone, Copy, ValueEnum)]
enum LogFormat {
    Text,
    Json,
}

/// A pipeline file (or none: every step with its defaults) and what the
/// command line overrides in it.
#[derive(clap::Args)]
struct PipelineArgs {
    /// The pipeline file (YAML). Without it, `-i` and `-o` are required and
    /// every step runs with its defaults (`pipelines/default.yaml`).
    pipeline: Option<PathBuf>,
    /// Override a key, e.g. `--set steps.prune.ratio=2` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// Override `input.source` (any OGR source: file, folder, `PG:…`, `/vsizip/…`).
    #[arg(short = 'i', long = "input", value_name = "SOURCE")]
    input: Option<String>,
    /// Override `input.layer` (a layer name); with `-i` and no `-l` the
    /// pipeline's layer is kept when the new source has it, otherwise the
    /// error lists the layers there are.
    #[arg(short = 'l', long = "layer", value_name = "LAYER")]
    layer: Option<String>,
    /// Override `output.path`.
    #[arg(short = 'o', long = "output", value_name = "OUT.gpkg")]
    output: Option<PathBuf>,
    /// Replace an existing output (`output.overwrite: true`).
    #[arg(long)]
    overwrite: bool,
}

/// The pipeline of a run without a pipeline file.
const DEFAULT_PIPELINE: &str = include_str!("../pipelines/default.yaml");

/// JSON-quoted, so that any path or name survives YAML parsing as a string.
fn quoted(s: &str) -> String {
    serde_json::to_string(s).unwrap_or_default()
}

impl PipelineArgs {
    /// Loads the file (or the built-in defaults) with the overrides; an
    /// invalid file logs and exits 78, a missing `-i`/`-o` without a file
    /// exits 2.
    fn load(&self) -> Result<config::Pipeline, ExitCode> {
        let mut ov = self.set.clone();
        if let Some(i) = &self.input {
            ov.push(format!("input.source={}", quoted(i)));
        }
        if let Some(l) = &self.layer {
            ov.push(format!("input.layer={}", quoted(l)));
        }
        if let Some(o) = &self.output {
            ov.push(format!("output.path={}", quoted(&o.display().to_string())));
        }
        if self.overwrite {
            ov.push("output.overwrite=true".into());
        }
        let loaded = match &self.pipeline {
            Some(path) => config::load(path, &ov),
            None => {
                if self.input.is_none() || self.output.is_none() {
                    tracing::error!(
                        "give a pipeline file, or run every step with its defaults with `-i SOURCE -o OUT.gpkg` (and `-l LAYER` for another layer than the first)"
                    );
                    return Err(ExitCode::from(EXIT_USAGE));
                }
                config::load_str(DEFAULT_PIPELINE, "pipelines/default.yaml (built in)", &ov)
            }
        };
        loaded.map_err(|e| {
            tracing::error!("{e}");
            ExitCode::from(EXIT_CONFIG)
        })
    }
}

#[derive(Subcommand)]
enum Command {
    /// Run a pipeline file, or every step with its defaults: `run -i SOURCE [-l LAYER] -o OUT.gpkg`.
    Run {
        #[command(flatten)]
        file: PipelineArgs,
        /// Worker threads (default: one per core).
        #[arg(long)]
        threads: Option<usize>,
        /// Without a terminal, log a progress line every so many seconds.
        #[arg(long, value_name = "SECONDS", default_value_t = 10.0, value_parser = seconds)]
        progress_every: f64,
    },
    /// Check a pipeline file and its input without processing anything.
    Validate {
        #[command(flatten)]
        file: PipelineArgs,
    },
    /// Score skeletons made by any tool with the paper's metrics.
    Score(ScoreArgs),
    /// Write the visual report of an output GeoPackage: every method's skeleton of the selected features side by side, with their scores (one self-contained HTML file).
    Report(ReportArgs),
    /// List the methods and steps with their options.
    Methods,
    /// Print the JSON Schema of the pipeline file.
    Schema,
}

/// The arguments of `skeletonise score`.
#[derive(clap::Args)]
struct ScoreArgs {
    /// Polygon source (any OGR data source).
    #[arg(long, value_name = "SRC")]
    polygons: String,
    /// Polygon layer (default: the first).
    #[arg(long, value_name = "LAYER")]
    polygons_layer: Option<String>,
    /// Skeleton source (lines; any OGR data source).
    #[arg(long, value_name = "SRC")]
    skeletons: String,
    /// Skeleton layer (default: the first).
    #[arg(long, value_name = "LAYER")]
    skeletons_layer: Option<String>,
    /// Join by key: the skeleton field holding the polygon's key (FID, or `--polygon-key`); without it, join by location.
    #[arg(long, value_name = "FIELD")]
    skeleton_key: Option<String>,
    /// Polygon field matched by `--skeleton-key` (default: the polygon FID).
    #[arg(long, value_name = "FIELD", requires = "skeleton_key")]
    polygon_key: Option<String>,
    /// Label for the `method` attribute (e.g. the tool's name).
    #[arg(long, default_value = "external")]
    label: String,
    /// Output GeoPackage.
    #[arg(short = 'o', long = "output", value_name = "OUT.gpkg")]
    output: PathBuf,
    /// Replace an existing output.
    #[arg(long)]
    overwrite: bool,
    /// Also write the bars layer.
    #[arg(long)]
    bars: bool,
    /// Target CRS for both sources (required when they are geographic).
    #[arg(long, value_name = "CRS")]
    reproject: Option<String>,
}

impl ScoreArgs {
    fn job(&self) -> skeletonise::external::ScoreJob {
        use skeletonise::config::{InputSpec, LayerRef, OutputSpec};
        use skeletonise::external::{Join, ScoreJob};
        let spec = |source: &String, layer: &Option<String>| InputSpec {
            source: source.clone(),
            layer: layer.clone().map(LayerRef::Name),
            where_: None,
            bbox: None,
            reproject: self.reproject.clone(),
            merge_adjacent: false,
            merge_by: None,
            connect: None,
            neighbours: None,
        };
        ScoreJob {
            polygons: spec(&self.polygons, &self.polygons_layer),
            skeletons: spec(&self.skeletons, &self.skeletons_layer),
            join: match &self.skeleton_key {
                Some(k) => Join::Key {
                    polygon_field: self.polygon_key.clone(),
                    skeleton_field: k.clone(),
                },
                None => Join::Location,
            },
            label: self.label.clone(),
            output: OutputSpec {
                path: self.output.display().to_string(),
                layer: "skeletons".into(),
                overwrite: self.overwrite,
                candidates: false,
                bars: self.bars,
                explode: false,
                widths: false,
                measures: Default::default(),
                report: None,
            },
        }
    }
}

/// A number of seconds ≥ 0 (a week at most).
fn seconds(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if (0.0..=604_800.0).contains(&v) => Ok(v),
        _ => Err(format!(
            "`{s}` is not a number of seconds between 0 and 604800"
        )),
    }
}

/// The arguments of `skeletonise report`.
#[derive(clap::Args)]
struct ReportArgs {
    /// The output GeoPackage of `skeletonise run` (or `score`).
    gpkg: PathBuf,
    /// The HTML file (default: beside the GeoPackage, extension .html).
    #[arg(short = 'o', long = "output", value_name = "REPORT.html")]
    output: Option<PathBuf>,
    /// Show the N features on which the methods disagree most (default 20).
    #[arg(long, value_name = "N", conflicts_with_all = ["fid", "where_"])]
    top: Option<usize>,
    /// Show these source FIDs (repeatable, or comma-separated).
    #[arg(
        long,
        value_name = "FID",
        value_delimiter = ',',
        conflicts_with = "where_"
    )]
    fid: Vec<u64>,
    /// Show the features whose skeleton row passes this OGR SQL filter, e.g. "kind = 'lake'".
    #[arg(long = "where", value_name = "SQL")]
    where_: Option<String>,
    /// Polygon source, when not where `skeletonise_runs` says the run read it.
    #[arg(long, value_name = "SRC")]
    polygons: Option<String>,
    /// Polygon layer (default: the layer the run read).
    #[arg(long, value_name = "LAYER", requires = "polygons")]
    polygons_layer: Option<String>,
    /// Reproject the polygons (default: as the run did).
    #[arg(long, value_name = "CRS", requires = "polygons")]
    reproject: Option<String>,
    /// Replace an existing report.
    #[arg(long)]
    overwrite: bool,
}

impl ReportArgs {
    fn job(&self) -> Result<skeletonise::reporting::ReportJob, String> {
        use skeletonise::config::{InputSpec, LayerRef};
        use skeletonise::report::Selection;
        let selection = match (&self.top, self.fid.is_empty(), &self.where_) {
            (Some(n), _, _) => Selection::Top(*n),
            (None, false, _) => Selection::Fids(self.fid.clone()),
            (None, true, Some(w)) => Selection::Where(w.clone()),
            (None, true, None) => Selection::default(),
        };
        selection
            .validate()
            .map_err(|(k, m)| format!("--{k}: {m}"))?;
        let recorded = skeletonise::io::readback::OutputFile::open(&self.gpkg)
            .ok()
            .and_then(|f| f.run().cloned());
        let polygons = self.polygons.as_ref().map(|source| InputSpec {
            source: source.clone(),
            layer: self
                .polygons_layer
                .clone()
                .or_else(|| recorded.as_ref().map(|r| r.input_layer.clone()))
                .filter(|l| !l.is_empty())
                .map(LayerRef::Name),
            where_: None,
            bbox: None,
            reproject: self
                .reproject
                .clone()
                .or_else(|| recorded.as_ref().and_then(|r| r.input_reproject.clone())),
            merge_adjacent: false,
            merge_by: None,
            connect: None,
            neighbours: None,
        });
        Ok(skeletonise::reporting::ReportJob {
            html: self
                .output
                .clone()
                .unwrap_or_else(|| self.gpkg.with_extension("html")),
            gpkg: self.gpkg.clone(),
            selection,
            polygons,
            overwrite: self.overwrite,
        })
    }
}

fn init_logging(cli: &Cli) {
    let level = if cli.quiet {
        "warn"
    } else {
        match cli.verbose {
            0 => "info",
            1 => "debug",
            _ => "trace",
        }
    };
    let filter = tracing_subscriber::EnvFilter::try_from_env("SKELETONISE_LOG")
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new(level));
    let b = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr);
    match cli.log_format {
        LogFormat::Json => b.json().flatten_event(true).init(),
        LogFormat::Text => b
            .with_target(false)
            .with_ansi(std::io::stderr().is_terminal())
            .init(),
    }
}

fn run_error(e: RunError) -> ExitCode {
    tracing::error!("{e}");
    match e {
        RunError::Rejected { .. } | RunError::Finish(_) => ExitCode::from(EXIT_REJECTED),
        // `--threads 0` or too many: a usage error, as `--threads abc` is.
        RunError::TooManyThreads { .. } => ExitCode::from(EXIT_USAGE),
        _ => ExitCode::from(EXIT_RUNTIME),
    }
}

fn main() -> ExitCode {
    no_huge_pages();
    prompt_purge();
    let cli = Cli::parse();
    init_logging(&cli);
    skeletonise::io::gdal_errors::install();
    // A panic (a bug; the per-feature path turns it into a rejection or a
    // failed method) is logged in the run's log format, not printed raw.
    std::panic::set_hook(Box::new(|info| {
        tracing::error!(target: "skeletonise::panic", "internal error: {info}");
    }));
    if let Err(e) = skeletonise::io::install_signal_handlers() {
        tracing::warn!(
            "signal handlers not installed ({e}): a killed run may leave its temporary file"
        );
    }
    match &cli.command {
        Command::Run {
            file,
            threads,
            progress_every,
        } => cmd_run(&cli, file, *threads, *progress_every),
        Command::Validate { file } => cmd_validate(file),
        Command::Score(args) => cmd_score(args),
        Command::Report(args) => cmd_report(args),
        Command::Methods => {
            print!(
                "{}",
                config::describe(&skeletonise::methods::Registry::builtin())
            );
            ExitCode::SUCCESS
        }
        Command::Schema => {
            println!(
                "{}",
                serde_json::to_string_pretty(&config::json_schema()).unwrap_or_default()
            );
            ExitCode::SUCCESS
        }
    }
}

/// Logs the summary line of a finished run.
fn log_summary(s: &pipeline::RunSummary) {
    let methods = s
        .methods
        .iter()
        .map(|(m, n)| format!("{m}={n}"))
        .collect::<Vec<_>>()
        .join(",");
    tracing::info!(
        read = s.read,
        written = s.written,
        rejected = s.rejected,
        filtered = s.filtered,
        rows = s.rows,
        seconds = format!("{:.2}", s.elapsed_s),
        methods = %methods,
        output = %s.output,
        "done: {} read, {} written, {} rejected, {} filtered in {:.2} s → {}",
        s.read, s.written, s.rejected, s.filtered, s.elapsed_s, s.output
    );
    if let Some(c) = &s.connect {
        tracing::info!(
            connections = c.connections,
            lines_used = c.lines_used,
            lines = c.lines,
            "connect: {} connections made, {} of the network's {} lines used",
            c.connections,
            c.lines_used,
            c.lines
        );
        if c.connections == 0 && s.written == 0 {
            tracing::warn!("connect: no connection made, as no polygon was written (the `rejected` layer says why)");
        } else if c.connections == 0 {
            tracing::warn!("connect: no line of the network touches, crosses or comes within `snap` of a written polygon; check that the network is the right layer and covers the polygons");
        }
    }
    for (m, t) in &s.stages {
        tracing::debug!(
            method = %m,
            skeleton_s = t.skeleton.as_secs_f64(),
            prune_extend_s = t.prune_extend.as_secs_f64(),
            score_s = t.score.as_secs_f64(),
            "{m}: skeleton {:.2} s, prune and extend {:.2} s, score {:.2} s (thread CPU time)",
            t.skeleton.as_secs_f64(),
            t.prune_extend.as_secs_f64(),
            t.score.as_secs_f64()
        );
    }
    if let Some(r) = &s.report {
        log_report(r);
    }
}

/// Logs the line of a written report.
fn log_report(r: &skeletonise::reporting::ReportSummary) {
    tracing::info!(
        sections = r.sections,
        bytes = r.bytes,
        seconds = format!("{:.2}", r.seconds),
        report = %r.path.display(),
        "report: {} features, {} KB in {:.2} s → {}",
        r.sections,
        r.bytes.div_ceil(1000),
        r.seconds,
        r.path.display()
    );
}

fn cmd_run(cli: &Cli, file: &PipelineArgs, threads: Option<usize>, every: f64) -> ExitCode {
    let p = match file.load() {
        Ok(p) => p,
        Err(c) => return c,
    };
    let opts = RunOptions {
        threads,
        progress: !cli.quiet
            && std::io::stderr().is_terminal()
            && matches!(cli.log_format, LogFormat::Text),
        batch_size: None,
        progress_every: Some(std::time::Duration::from_secs_f64(every)),
    };
    match pipeline::run(&p, &opts) {
        Ok(s) => {
            log_summary(&s);
            ExitCode::SUCCESS
        }
        Err(e) => run_error(e),
    }
}

fn cmd_validate(file: &PipelineArgs) -> ExitCode {
    let p = match file.load() {
        Ok(p) => p,
        Err(c) => return c,
    };
    match pipeline::validate(&p) {
        Ok(info) => {
            let fields: Vec<&str> = info.fields.iter().map(|f| f.name.as_str()).collect();
            let n =
                |c: Option<u64>| c.map_or_else(|| "an unknown number of".into(), |n| n.to_string());
            println!(
                "{}: valid. input `{}` layer `{}`: {} features ({} after filters), CRS {}, fields: {}; output {}{}",
                p.origin,
                info.source,
                info.layer,
                n(info.total),
                n(info.selected),
                info.crs_name,
                fields.join(", "),
                p.file.output.path,
                p.file
                    .output
                    .report_path()
                    .map_or_else(String::new, |r| format!(", report {}", r.display()))
            );
            ExitCode::SUCCESS
        }
        Err(e) => run_error(e),
    }
}

fn cmd_score(args: &ScoreArgs) -> ExitCode {
    match skeletonise::external::score_external(&args.job(), args.bars) {
        Ok(s) => {
            log_summary(&s);
            ExitCode::SUCCESS
        }
        Err(e) => run_error(e),
    }
}

fn cmd_report(args: &ReportArgs) -> ExitCode {
    let job = match args.job() {
        Ok(j) => j,
        Err(e) => {
            tracing::error!("{e}");
            return ExitCode::from(EXIT_USAGE);
        }
    };
    match skeletonise::reporting::write_report(&job) {
        Ok(r) => {
            log_report(&r);
            ExitCode::SUCCESS
        }
        Err(e) => {
            tracing::error!("{e}");
            ExitCode::from(EXIT_RUNTIME)
        }
    }
}

#[cfg(test)]
mod tests {
    /// The process asks for 4 KiB pages: the kernel reports huge pages off.
    #[cfg(target_os = "linux")]
    #[test]
    fn huge_pages_are_off_for_the_process() {
        let thp = || {
            std::fs::read_to_string("/proc/self/status")
                .unwrap()
                .lines()
                .find_map(|l| l.strip_prefix("THP_enabled:").map(|v| v.trim().to_string()))
        };
        let Some(before) = thp() else {
            // Kernels before 5.0 do not report it.
            eprintln!("no THP_enabled in /proc/self/status: not checked");
            return;
        };
        super::no_huge_pages();
        assert_eq!(thp().as_deref(), Some("0"), "was {before}");
    }

    /// The option index is mimalloc's `purge_delay`: it holds mimalloc 3's
    /// default (1 000 ms) unless already set, and `prompt_purge` sets it.
    #[test]
    fn the_purge_delay_is_the_option_set() {
        if std::env::var_os("MIMALLOC_PURGE_DELAY").is_some() {
            return;
        }
        // SAFETY: as in `prompt_purge`.
        let get = || unsafe { libmimalloc_sys::mi_option_get(super::MI_OPTION_PURGE_DELAY) };
        let before = get();
        assert!(
            before == super::MI_DEFAULT_PURGE_DELAY || before == 100,
            "option {} holds {before}: not mimalloc 3's purge_delay",
            super::MI_OPTION_PURGE_DELAY
        );
        super::prompt_purge();
        assert_eq!(get(), 100);
    }
}
