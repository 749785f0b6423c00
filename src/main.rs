//! `skeletonise` command line: parses arguments, sets up logging, maps errors
//! to exit codes (0 ok, 1 runtime failure, 2 usage, 65 rejected features under
//! `on_error: fail`, 78 invalid pipeline file).

use clap::{Parser, Subcommand, ValueEnum};
use skeletonise::config;
use skeletonise::methods::MethodId;
use skeletonise::pipeline::{self, RunError, RunOptions};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;

const EXIT_RUNTIME: u8 = 1;
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

/// A pipeline file and what the command line overrides in it.
#[derive(clap::Args)]
struct PipelineArgs {
    /// The pipeline file (YAML).
    pipeline: PathBuf,
    /// Override a key, e.g. `--set steps.prune.ratio=2` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// Override `input.source`.
    #[arg(short = 'i', long = "input", value_name = "SOURCE")]
    input: Option<String>,
    /// Override `output.path`.
    #[arg(short = 'o', long = "output", value_name = "OUT.gpkg")]
    output: Option<PathBuf>,
}

impl PipelineArgs {
    /// Loads the file with the overrides; an invalid file logs and exits 78.
    fn load(&self) -> Result<config::Pipeline, ExitCode> {
        let mut ov = self.set.clone();
        // Quoted so that any path survives YAML parsing as a string.
        if let Some(i) = &self.input {
            ov.push(format!(
                "input.source={}",
                serde_json::to_string(i).unwrap_or_default()
            ));
        }
        if let Some(o) = &self.output {
            ov.push(format!(
                "output.path={}",
                serde_json::to_string(&o.display().to_string()).unwrap_or_default()
            ));
        }
        config::load(&self.pipeline, &ov).map_err(|e| {
            tracing::error!("{e}");
            ExitCode::from(EXIT_CONFIG)
        })
    }
}

#[derive(Subcommand)]
enum Command {
    /// Run a pipeline file.
    Run {
        #[command(flatten)]
        file: PipelineArgs,
        /// Worker threads (default: one per core).
        #[arg(long)]
        threads: Option<usize>,
    },
    /// Check a pipeline file and its input without processing anything.
    Validate {
        #[command(flatten)]
        file: PipelineArgs,
    },
    /// Score skeletons made by any tool with the paper's metrics.
    Score {
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
    },
    /// List the methods and steps with their options.
    Methods,
    /// Print the JSON Schema of the pipeline file.
    Schema,
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
        RunError::Rejected { .. } => ExitCode::from(EXIT_REJECTED),
        _ => ExitCode::from(EXIT_RUNTIME),
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    init_logging(&cli);
    match &cli.command {
        Command::Run { file, threads } => {
            let p = match file.load() {
                Ok(p) => p,
                Err(c) => return c,
            };
            let opts = RunOptions {
                threads: *threads,
                progress: !cli.quiet
                    && std::io::stderr().is_terminal()
                    && matches!(cli.log_format, LogFormat::Text),
                batch_size: None,
            };
            match pipeline::run(&p, &opts) {
                Ok(s) => {
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
                    ExitCode::SUCCESS
                }
                Err(e) => run_error(e),
            }
        }
        Command::Validate { file } => {
            let p = match file.load() {
                Ok(p) => p,
                Err(c) => return c,
            };
            match pipeline::validate(&p) {
                Ok(info) => {
                    let fields = info
                        .fields
                        .iter()
                        .map(|f| f.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ");
                    println!(
                        "{}: valid. input `{}` layer `{}`: {} features ({} after filters), CRS {}, fields: {}; output {}",
                        p.origin, info.source, info.layer, info.total, info.selected, info.crs_name, fields, p.file.output.path
                    );
                    ExitCode::SUCCESS
                }
                Err(e) => run_error(e),
            }
        }
        Command::Score {
            polygons,
            polygons_layer,
            skeletons,
            skeletons_layer,
            skeleton_key,
            polygon_key,
            label,
            output,
            overwrite,
            bars,
            reproject,
        } => {
            let spec = |source: &String, layer: &Option<String>| skeletonise::io::InputSpec {
                source: source.clone(),
                layer: layer.clone().map(skeletonise::io::LayerRef::Name),
                where_: None,
                bbox: None,
                reproject: reproject.clone(),
            };
            let job = skeletonise::external::ScoreJob {
                polygons: spec(polygons, polygons_layer),
                skeletons: spec(skeletons, skeletons_layer),
                join: match skeleton_key {
                    Some(k) => skeletonise::external::Join::Key {
                        polygon_field: polygon_key.clone(),
                        skeleton_field: k.clone(),
                    },
                    None => skeletonise::external::Join::Location,
                },
                label: label.clone(),
                output: skeletonise::io::writer::OutputSpec {
                    path: output.display().to_string(),
                    layer: "skeletons".into(),
                    overwrite: *overwrite,
                    candidates: false,
                    bars: *bars,
                    explode: false,
                    widths: false,
                },
            };
            match skeletonise::external::score_external(&job, *bars) {
                Ok(s) => {
                    tracing::info!(
                        read = s.read,
                        written = s.written,
                        rejected = s.rejected,
                        seconds = format!("{:.2}", s.elapsed_s),
                        output = %s.output,
                        "scored: {} polygons, {} with a skeleton, {} without → {}",
                        s.read, s.written, s.rejected, s.output
                    );
                    ExitCode::SUCCESS
                }
                Err(e) => run_error(e),
            }
        }
        Command::Methods => {
            println!("Methods (skeleton step, `methods: [...]`):");
            for m in MethodId::builtin() {
                println!("  {:<5} {}", m.as_str(), m.description());
            }
            println!(
                "\nSteps (in this order; only `skeleton` is required):\n  \
                 prepare   make_valid (bool, default true), min_area (CRS units², default 0)\n  \
                 skeleton  methods (list, default [MA, StSk, DVD, CDT, VD]), densify ({{factor: k}} default 4 | {{spacing: d}}), max_points (default 2000000), arc_tolerance ({{relative: f}} default 0.001 | {{absolute: d}}), reference (method whose pruned skeleton sets every method's legs, default MA)\n  \
                 prune     mode (significance | length | trunk | none), ratio (default 1.0), arm_ratio (default 1.0), min_length (default 0), structure (shared | independent, default shared)\n  \
                 extend    mode (centred | ray | nearest | none, default centred)\n  \
                 score     (no options)\n  \
                 select    by (distortion | deviation | deviation_parts | distortion_sum), min_coverage (default 0.9), coverage_slack (default 0.25), tie (default 0.0001)\n\n\
                 Selection: among candidates with hits, those with coverage >= min(min_coverage, best coverage - coverage_slack)\n  \
                 are eligible; the smallest `by` wins, distortions within `tie` of it count as equal and go to the method\n  \
                 listed first. With structure: shared every method has the reference's legs reaching the boundary at the\n  \
                 same places, so the metric, not a few points of coverage, decides.\n\n\
                 `skeletonise schema` prints the full JSON Schema."
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
