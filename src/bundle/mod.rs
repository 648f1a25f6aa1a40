//! `ferroc bundle`: check a model, plan it, and write a Cargo workspace with one program
//! per part whose `main.rs` makes the Builder calls `ferroc run` makes, plus the
//! resolved model, `manifest.json`, launch scripts and systemd units. See docs/bundle.md.
//!
//! The fixed text of the generated files comes from askama templates (`templates/`:
//! `main.rs`, the Cargo manifests, the launch script, the systemd unit), checked at
//! compile time; what varies with the model in `main.rs` (the Builder calls, imports, link
//! constants) is written by small emitters in rustfmt's layout (`rust.rs`, `links.rs`,
//! `code.rs`), and the resolved model by `resolved.rs`. Model content reaches them only
//! through the validation in `layout.rs` and the escaping in `text.rs`, which the
//! templates apply by file type (`escape.rs`, `askama.toml`); files are written only
//! below the output folder (`out.rs`). The crates it depends on are chosen and found in
//! `deps.rs`, the files put together in `generate.rs`, source places named in `names.rs`.

mod code;
mod deps;
mod escape;
mod fields;
mod files;
mod generate;
mod layout;
mod links;
mod literals;
mod names;
mod out;
mod resolved;
mod ros2;
mod rust;
pub(crate) mod sha256;
pub(crate) mod text;

use deps::{dependencies, one_runtime, path_crates};
use ferroc_compiler::plan;
use files::Dependency;
use generate::generate;
use names::Names;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

const TOOL_VERSION: &str = env!("CARGO_PKG_VERSION");

#[derive(clap::Args)]
pub struct BundleArgs {
    /// The application model
    model: PathBuf,
    /// The folder to write the bundle to (created if missing; must be empty unless --force)
    #[arg(short, long = "output", value_name = "DIR")]
    output: PathBuf,
    /// Write into a non-empty DIR, replacing the bundle's files (other files stay)
    #[arg(long)]
    force: bool,
    /// How the generated crates find the runtime and component crates
    #[arg(long, value_enum, default_value_t = Deps::Path)]
    deps: Deps,
    /// A value for a parameter declared with `cmdline=NAME`, fixed into the bundle (repeatable)
    #[arg(long = "param", value_name = "NAME=VALUE")]
    params: Vec<String>,
    /// Where the systemd units expect the installed binaries: PREFIX/bin [default: /opt/APPLICATION]
    #[arg(long, value_name = "PREFIX")]
    prefix: Option<String>,
    /// Serve inspection (`PROGRAM --inspect`) in every part's program; parts linked to
    /// others serve it anyway (it runs on their Zenoh), the others link no Zenoh without it
    #[arg(long)]
    inspect: bool,
    /// Extra folders searched for `NAME.lib.xml` manifests (also FERROC_LIB_PATH)
    #[arg(long, value_name = "DIR")]
    lib_path: Vec<PathBuf>,
}

#[derive(Clone, Copy, clap::ValueEnum, PartialEq)]
enum Deps {
    /// By path, relative to DIR, to the crates of the checkout ferroc was built from
    Path,
    /// By version, from a registry (the library manifests' `rust-crate` and `version`)
    Version,
}

/// Each message on its own line(s); exit code 1.
fn report(messages: &[String]) -> ExitCode {
    messages.iter().for_each(|m| eprintln!("{m}"));
    ExitCode::from(1)
}

fn usage_error(message: &str) -> ExitCode {
    eprintln!("error: {message}");
    ExitCode::from(2)
}

pub fn run(args: BundleArgs) -> ExitCode {
    let cmdline = match cmdline_params(&args) {
        Ok(c) => c,
        Err(code) => return code,
    };
    let result = match crate::check_first::without_errors(&args.model, &args.lib_path) {
        Ok(r) => r,
        Err(code) => return code,
    };
    let Some(app) = result.app.as_ref() else {
        return ExitCode::from(1);
    };
    let names = Names::new(&args.model, &result.sources);
    let plan = match plan_built_in(app, &result, &cmdline, &names) {
        Ok(plan) => plan,
        Err(code) => return code,
    };
    let layout = match layout::layout(app, &result.libraries, &plan) {
        Ok(l) => l,
        Err(problems) => {
            for p in problems {
                eprintln!("{}: error: {}", names.at(p.span), p.what);
            }
            return ExitCode::from(1);
        }
    };
    let prefix = args
        .prefix
        .clone()
        .unwrap_or_else(|| format!("/opt/{}", layout.application));
    // Before anything is written: a bundle cargo cannot build is not made.
    let found = match path_crates(&layout, &result, args.deps) {
        Ok(found) => found,
        Err(problems) => return report(&problems),
    };
    let conflicts = one_runtime(&found);
    if !conflicts.is_empty() {
        return report(&conflicts);
    }
    let root = match out::prepare_dir(&args.output, args.force) {
        Ok(r) => r,
        Err(e) => return usage_error(&e),
    };
    let deps = dependencies(&layout, &args, &root, &found);
    let deps = match deps.and_then(|d| no_clash(&layout, d)) {
        Ok(d) => d,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(1);
        }
    };
    let generated = match generate(
        &args, &result, &plan, &layout, &deps, &cmdline, &names, &prefix,
    ) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(1);
        }
    };
    if let Err(e) = out::write(&root, &generated, |staged| {
        format_generated(staged, &layout)
    }) {
        return usage_error(&e);
    }
    let parts: Vec<&str> = layout.parts.iter().map(|p| p.name.as_str()).collect();
    eprintln!(
        "bundled `{}` ({} part(s): {}) into {}\n  build: cargo build --release --manifest-path {}\n  run:   {}/launch/<host>.sh, or target/release/<application>-<part>",
        layout.application,
        parts.len(),
        parts.join(", "),
        args.output.display(),
        args.output.join("Cargo.toml").display(),
        args.output.display()
    );
    ExitCode::SUCCESS
}

/// The `--param NAME=VALUE` pairs, with `--prefix` checked; exit code 2 for a malformed
/// one (reported).
fn cmdline_params(args: &BundleArgs) -> Result<Vec<(String, String)>, ExitCode> {
    let cmdline = ferroc_host::run::param_pairs(&args.params).map_err(|e| usage_error(&e))?;
    if let Some(prefix) = &args.prefix {
        if !files::valid_prefix(prefix) {
            return Err(usage_error(&format!(
                "--prefix {}: give an absolute path of plain names, e.g. /opt/robot",
                text::comment(prefix)
            )));
        }
    }
    Ok(cmdline)
}

/// The plan of the model, refused (exit code 1) where the runtime cannot realise it or
/// a module type built into this ferroc differs from its manifest.
fn plan_built_in(
    app: &ferroc_compiler::ir::Application,
    result: &ferroc_compiler::CheckResult,
    cmdline: &[(String, String)],
    names: &Names<'_>,
) -> Result<plan::Plan, ExitCode> {
    let (plan, unsupported) = plan::plan(app, &result.libraries, cmdline);
    for p in &unsupported {
        eprintln!("{}: error: {}", names.at(p.span), p.what);
    }
    if !unsupported.is_empty() {
        return Err(ExitCode::from(1));
    }
    // Types built into this ferroc are the same code the bundle compiles: check them
    // against their manifests as `ferroc run` does. Others are checked when built.
    let registry = crate::run::interfaces_of(&crate::run::registry());
    let mut built_in = plan.clone();
    built_in
        .modules
        .retain(|m| registry.contains_key(&m.type_name));
    if let Err(lines) =
        crate::run::interfaces_agree(&built_in, &registry, &result.libraries, &result.sources)
    {
        lines.iter().for_each(|l| eprintln!("{l}"));
        return Err(ExitCode::from(1));
    }
    Ok(plan)
}

/// `deps`, unless a part's program would have the name of a crate it depends on.
fn no_clash(layout: &layout::Layout<'_>, deps: Vec<Dependency>) -> Result<Vec<Dependency>, String> {
    for d in &deps {
        if let Some(p) = layout
            .parts
            .iter()
            .find(|p| p.package == d.package || p.package == "ctrlc")
        {
            return Err(format!(
                "the program of part `{}` would be called `{}`, like a crate it depends on; rename the part",
                p.name, p.package
            ));
        }
    }
    Ok(deps)
}

/// The generated code is emitted in rustfmt's layout already; where rustfmt is installed
/// it also runs over it (with the bundle's `rustfmt.toml`), for layouts of unusual
/// models the emitter does not foresee. Formatting never fails the bundle.
fn format_generated(root: &Path, layout: &layout::Layout<'_>) {
    let mains: Vec<PathBuf> = layout
        .parts
        .iter()
        .map(|p| root.join("parts").join(&p.name).join("src/main.rs"))
        .collect();
    let _ = std::process::Command::new("rustfmt")
        .arg("--edition=2021")
        .arg("--config-path")
        .arg(root.join("rustfmt.toml"))
        .args(&mains)
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status();
}
