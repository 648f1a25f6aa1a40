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
//! below the output folder (`out.rs`).

mod code;
mod escape;
mod fields;
mod files;
mod layout;
mod links;
mod literals;
mod out;
mod resolved;
mod ros2;
mod rust;
pub(crate) mod sha256;
pub(crate) mod text;

use ferroc_compiler::plan;
use ferroc_compiler::source::{SourceMap, Span};
use files::{Dependency, Source};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

const TOOL_VERSION: &str = env!("CARGO_PKG_VERSION");
/// The checkout this ferroc was built from: the runtime and component crates live here.
const CHECKOUT: &str = env!("CARGO_MANIFEST_DIR");

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
    let root = match out::prepare_dir(&args.output, args.force) {
        Ok(r) => r,
        Err(e) => return usage_error(&e),
    };
    let deps = match dependencies(&layout, args.deps, &root).and_then(|d| no_clash(&layout, d)) {
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

/// Source locations as `file:line:col`, files named relative to the model's folder so
/// the bundle does not depend on where ferroc was started.
struct Names<'s> {
    base: Option<PathBuf>,
    sources: &'s SourceMap,
    model_file: String,
}

impl<'s> Names<'s> {
    fn new(model: &Path, sources: &'s SourceMap) -> Self {
        let base = model
            .canonicalize()
            .ok()
            .and_then(|p| p.parent().map(Path::to_path_buf));
        let model_file = model
            .file_name()
            .map_or_else(|| "model.xml".into(), |f| f.to_string_lossy().into_owned());
        Names {
            base,
            sources,
            model_file,
        }
    }

    fn file(&self, file: &ferroc_compiler::source::SourceFile) -> String {
        if let Some(rel) = self
            .base
            .as_ref()
            .and_then(|b| file.path.strip_prefix(b).ok())
        {
            if !rel.as_os_str().is_empty() {
                return rel.to_string_lossy().into_owned();
            }
        }
        if file.path.as_os_str().is_empty() {
            return file.name.clone(); // built in
        }
        let rel = self.base.as_ref().and_then(|b| relative(b, &file.path));
        rel.unwrap_or_else(|| file.name.clone())
    }

    fn at(&self, span: Span) -> String {
        let file = self.sources.get(span.file);
        let (line, col) = file.line_col(span.start);
        format!("{}:{line}:{col}", self.file(file))
    }
}

/// `to` relative to the folder `from` (both absolute), with `/` separators.
fn relative(from: &Path, to: &Path) -> Option<String> {
    let from: Vec<_> = from.components().collect();
    let to: Vec<_> = to.components().collect();
    let common = from.iter().zip(&to).take_while(|(a, b)| a == b).count();
    // Sharing only the root (`/`): an absolute path reads better than `../../..`.
    if common <= 1 {
        return None;
    }
    let mut parts: Vec<String> = vec!["..".into(); from.len() - common];
    parts.extend(
        to[common..]
            .iter()
            .map(|c| c.as_os_str().to_string_lossy().into_owned()),
    );
    Some(if parts.is_empty() {
        ".".into()
    } else {
        parts.join("/")
    })
}

/// The Cargo package of the standard library, whose recorders every program has.
const STD_PACKAGE: &str = "ferroc-std";

/// The runtime and the component crates the parts use, by path or by version.
fn dependencies(
    layout: &layout::Layout<'_>,
    deps: Deps,
    root: &Path,
) -> Result<Vec<Dependency>, String> {
    let checkout = Path::new(CHECKOUT);
    let ours = |package: &str, folder: &str, what: &str| -> Result<Dependency, String> {
        Ok(Dependency {
            package: package.into(),
            source: match deps {
                Deps::Path => by_path(root, checkout.join(folder), what)?,
                Deps::Version => Source::Version(TOOL_VERSION.into()),
            },
        })
    };
    let mut out = vec![ours("ferroc-runtime", "runtime", "the runtime")?];
    // Every program serves inspection on request (`--inspect`, docs/inspect.md).
    out.push(ours("ferroc-inspect", "inspect", "the inspection server")?);
    // Programs of linked parts and of ROS 2 nodes talk over Zenoh (only when some
    // part needs it).
    if layout.parts.iter().any(|p| p.uses_zenoh()) {
        out.push(ours("ferroc-zenoh", "zenoh-link", "the Zenoh transport")?);
    }
    for lib in layout.libraries.values() {
        out.push(Dependency {
            package: lib.package.clone(),
            source: library_source(lib, deps, root)?,
        });
    }
    // Every program can record (`--record`) with the standard library's recorders.
    if !out.iter().any(|d| d.package == STD_PACKAGE) {
        let folder = format!("components/{STD_PACKAGE}");
        out.push(ours(STD_PACKAGE, &folder, "the standard library")?);
    }
    Ok(out)
}

/// The crate in folder `dir` as a path relative to the bundle's `root` (absolute when
/// they share only `/`).
fn by_path(root: &Path, dir: PathBuf, what: &str) -> Result<Source, String> {
    let dir = dir.canonicalize().map_err(|_| {
        format!(
            "{what}: no crate at {}; build ferroc from a checkout, or use --deps version",
            dir.display()
        )
    })?;
    Ok(Source::Path(
        relative(root, &dir).unwrap_or_else(|| dir.to_string_lossy().into_owned()),
    ))
}

/// Where a library's crate comes from: the registry for `rust-crate="PACKAGE@VERSION"`
/// whatever `--deps` says; else by its version, or by path next to its manifest or
/// among the checkout's components.
fn library_source(lib: &layout::Library, deps: Deps, root: &Path) -> Result<Source, String> {
    if let Some(version) = &lib.registry {
        return Ok(Source::Version(version.clone()));
    }
    match deps {
        Deps::Version => Ok(Source::Version(lib.version.clone().ok_or_else(|| {
            format!("the library `{}` declares no version: --deps version needs <library version=\"x.y.z\">", lib.name)
        })?)),
        Deps::Path => {
            let mut candidates: Vec<PathBuf> = Vec::new();
            if let Some(dir) = lib.manifest.as_ref().and_then(|m| m.parent()) {
                candidates.push(dir.join(&lib.package));
            }
            candidates.push(Path::new(CHECKOUT).join("components").join(&lib.package));
            let found = candidates.iter().find(|c| c.join("Cargo.toml").is_file());
            match found {
                Some(dir) => by_path(root, dir.clone(), &lib.name),
                None => Err(format!(
                    "the crate `{}` of library `{}` was not found (looked in {}); build it there, or use --deps version",
                    lib.package,
                    lib.name,
                    candidates.iter().map(|c| c.display().to_string()).collect::<Vec<_>>().join(", ")
                )),
            }
        }
    }
}

/// Every file of the bundle, in memory.
#[allow(clippy::too_many_arguments)]
fn generate(
    args: &BundleArgs,
    result: &ferroc_compiler::CheckResult,
    plan: &plan::Plan,
    layout: &layout::Layout<'_>,
    deps: &[Dependency],
    cmdline: &[(String, String)],
    names: &Names<'_>,
    prefix: &str,
) -> Result<out::Files, String> {
    let mut files = out::Files::default();
    files.add(
        "Cargo.toml",
        files::workspace_toml(layout, deps, TOOL_VERSION),
    )?;
    files.add(
        "rustfmt.toml",
        "# The layout of the generated code (rustfmt's defaults).\nedition = \"2021\"\n",
    )?;
    if args.deps == Deps::Path {
        // The versions this checkout is built and tested with.
        if let Ok(lock) = std::fs::read(Path::new(CHECKOUT).join("Cargo.lock")) {
            files.add("Cargo.lock", lock)?;
        }
    }
    add_parts(&mut files, layout, deps, names, prefix)?;
    let mut hosts: Vec<&str> = layout.parts.iter().map(|p| p.host.as_str()).collect();
    hosts.sort();
    hosts.dedup();
    for host in hosts {
        files.add_executable(
            &format!("launch/{host}.sh"),
            files::launch_script(layout, host, TOOL_VERSION),
        )?;
    }
    add_resolved_model(&mut files, result, plan, layout, cmdline, names)?;
    let model_bytes = std::fs::read(&args.model)
        .map_err(|e| format!("cannot read {}: {e}", args.model.display()))?;
    let sources = result
        .sources
        .files()
        .map(|(_, f)| (names.file(f), sha256::hex(f.text.as_bytes())))
        .collect();
    let mut listed: Vec<String> = files.paths().map(str::to_string).collect();
    listed.push("manifest.json".into());
    listed.sort();
    let manifest = files::ManifestInput {
        tool_version: TOOL_VERSION,
        model_file: &names.model_file,
        model_sha256: sha256::hex(&model_bytes),
        sources,
        deps,
        files: listed,
    };
    files.add("manifest.json", files::manifest_json(layout, &manifest))?;
    Ok(files)
}

/// Each part's Cargo manifest, `main.rs` and systemd unit.
fn add_parts(
    files: &mut out::Files,
    layout: &layout::Layout<'_>,
    deps: &[Dependency],
    names: &Names<'_>,
    prefix: &str,
) -> Result<(), String> {
    let at = |span: Span| names.at(span);
    let addresses: Vec<(String, String)> = (layout.parts.iter())
        .map(|p| (p.name.clone(), p.address.clone()))
        .collect();
    let cx = rust::Context {
        application: &layout.application,
        seed: layout.seed,
        parts: &addresses,
        periods: &layout.periods,
        model_file: &names.model_file,
        tool_version: TOOL_VERSION,
        at: &at,
    };
    for (i, part) in layout.parts.iter().enumerate() {
        let zenoh = deps.iter().find(|d| d.package == "ferroc-zenoh");
        let inspect = deps.iter().find(|d| d.package == "ferroc-inspect");
        let mut part_deps: Vec<&Dependency> = std::iter::once(&deps[0])
            .chain(inspect)
            .chain(zenoh.filter(|_| part.uses_zenoh()))
            .chain(part.libraries.iter().filter_map(|l| {
                let package = &layout.libraries.get(l)?.package;
                deps.iter().find(|d| d.package == *package)
            }))
            .collect();
        if !part_deps.iter().any(|d| d.package == STD_PACKAGE) {
            part_deps.extend(deps.iter().find(|d| d.package == STD_PACKAGE));
        }
        let dir = format!("parts/{}", part.name);
        files.add(
            &format!("{dir}/Cargo.toml"),
            files::part_toml(layout, i, &part_deps, TOOL_VERSION),
        )?;
        files.add(&format!("{dir}/src/main.rs"), rust::main_rs(part, &cx))?;
        files.add(
            &format!("systemd/{}.service", part.package),
            files::systemd_unit(layout, i, prefix, TOOL_VERSION),
        )?;
    }
    Ok(())
}

/// The resolved model, with copies of the manifests it uses.
fn add_resolved_model(
    files: &mut out::Files,
    result: &ferroc_compiler::CheckResult,
    plan: &plan::Plan,
    layout: &layout::Layout<'_>,
    cmdline: &[(String, String)],
    names: &Names<'_>,
) -> Result<(), String> {
    let mut manifests = Vec::new();
    for lib in &result.libraries.libraries {
        if !text::is_name(&lib.name) {
            return Err(format!(
                "the library name `{}` cannot name a file",
                text::comment(&lib.name)
            ));
        }
        if lib.path.as_os_str().is_empty() {
            manifests.push((lib.name.clone(), None));
            continue;
        }
        let rel = format!("libraries/{}.lib.xml", lib.name);
        files.add(
            &format!("model/{rel}"),
            result.sources.get(lib.file).text.clone(),
        )?;
        manifests.push((lib.name.clone(), Some(rel)));
    }
    let app = result.app.as_ref().ok_or("no application")?;
    let resolved = resolved::document(
        app,
        &result.libraries,
        plan,
        &manifests,
        cmdline,
        &names.model_file,
        TOOL_VERSION,
    );
    files.add(&format!("model/{}.xml", layout.application), resolved)?;
    Ok(())
}
