//! `ferroc graph`: the application (behaviour networks in iB2C style) as DOT or SVG.

use clap::ValueEnum;
use ferroc_compiler::diagnostic::Severity;
use ferroc_compiler::{check_model, Policy};
use std::io::Write as _;
use std::path::PathBuf;
use std::process::{Command, ExitCode, Stdio};

#[derive(clap::Args)]
pub struct GraphArgs {
    /// The application model
    model: PathBuf,
    /// Output format: DOT text, or SVG rendered by Graphviz `dot` (must be on PATH)
    #[arg(long, value_enum, default_value_t = GraphFormat::Dot)]
    format: GraphFormat,
    /// Write to this file instead of standard output
    #[arg(short, long, value_name = "FILE")]
    output: Option<PathBuf>,
    /// Extra folders searched for `NAME.lib.xml` manifests (also FERROC_LIB_PATH)
    #[arg(long, value_name = "DIR")]
    lib_path: Vec<PathBuf>,
}

#[derive(Clone, Copy, ValueEnum, PartialEq)]
enum GraphFormat {
    /// Graphviz DOT text
    Dot,
    /// SVG, rendered with Graphviz `dot -Tsvg`
    Svg,
}

pub fn run(args: GraphArgs) -> ExitCode {
    let options = crate::loader_options(&args.lib_path, false);
    let result = match check_model(&args.model, &options, &Policy::default()) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let Some(app) = result.app.as_ref() else {
        eprintln!(
            "error: {} is not an application model; `ferroc check` explains why",
            args.model.display()
        );
        return ExitCode::from(2);
    };
    let errors = result
        .diagnostics
        .iter()
        .filter(|d| d.severity == Severity::Error)
        .count();
    if errors > 0 {
        eprintln!(
            "warning: the model has {errors} error(s); the graph shows what resolved \
             (`ferroc check` explains them)"
        );
    }
    let dot = ferroc_compiler::graph::dot(app, &result.libraries);
    let bytes = match args.format {
        GraphFormat::Dot => dot.into_bytes(),
        GraphFormat::Svg => match render_svg(&dot) {
            Ok(svg) => svg,
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::from(2);
            }
        },
    };
    let written = match &args.output {
        Some(path) => std::fs::write(path, &bytes)
            .map_err(|e| format!("cannot write {}: {e}", path.display())),
        None => return crate::output::stdout_then(&bytes, ExitCode::SUCCESS),
    };
    match written {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

/// Runs Graphviz `dot -Tsvg` on the DOT text.
fn render_svg(dot: &str) -> Result<Vec<u8>, String> {
    let mut child = Command::new("dot")
        .arg("-Tsvg")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| match e.kind() {
            std::io::ErrorKind::NotFound => "Graphviz `dot` is not on PATH; install Graphviz \
                 (e.g. `apt install graphviz`) or use `--format dot` and render the text \
                 elsewhere"
                .to_string(),
            _ => format!("cannot run Graphviz `dot`: {e}"),
        })?;
    // Write on another thread: `dot` may fill its output pipe before reading all input.
    let mut stdin = child.stdin.take().ok_or("cannot write to Graphviz `dot`")?;
    let text = dot.to_owned();
    let writer = std::thread::spawn(move || stdin.write_all(text.as_bytes()));
    let out = child
        .wait_with_output()
        .map_err(|e| format!("Graphviz `dot` failed: {e}"))?;
    let _ = writer.join();
    if !out.status.success() {
        return Err(format!(
            "Graphviz `dot` failed: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        ));
    }
    Ok(out.stdout)
}
