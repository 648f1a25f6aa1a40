//! `ferroc new`: start a library crate or a model that checks and runs as written.
//!
//! `ferroc new library NAME` writes a crate whose one module type has an input, an
//! output and a parameter, its manifest, a unit test and a model using it;
//! docs/writing-modules.md walks through exactly these files.

use crate::bundle::text::{is_name, toml_str, xml};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(clap::Args)]
pub struct NewArgs {
    #[command(subcommand)]
    what: What,
}

#[derive(clap::Subcommand)]
enum What {
    /// A library crate: Cargo.toml, NAME.lib.xml, src/lib.rs (one module type with a
    /// test) and demo.xml, a model using it
    #[command(
        long_about = "Write a library crate in DIR (default: ./NAME): Cargo.toml \
(depending on this ferroc's runtime by path), the manifest NAME.lib.xml, src/lib.rs with one \
module type (an input, an output, a parameter), its registration and a unit test, and demo.xml, \
a model using it. Beside them .cargo/config.toml, which builds the crate in ferroc's runner \
cache (`ferroc cache`) rather than a target folder of its own, and Cargo.lock, a copy of the \
checkout's: the versions ferroc was built with, compiled once for both. Then:\n\n  \
ferroc run NAME/demo.xml --cycles 5\n  \
ferroc types export --check --lib-path NAME\n  (cd NAME && cargo test)\n\n\
docs/writing-modules.md explains every file."
    )]
    Library {
        /// The library's name: lowercase letters, digits and `_` (the package name is
        /// the same with `-`)
        name: String,
        /// Folder to create (must not exist or be empty)
        #[arg(long, value_name = "DIR")]
        dir: Option<PathBuf>,
    },
    /// A model: one part, one thread container, one instance of each module type of
    /// the library given (or a standard-library example)
    Model {
        /// The model file to write (must not exist); `-` writes it to standard output
        file: PathBuf,
        /// A library manifest whose module types the model instantiates
        #[arg(long, value_name = "MANIFEST")]
        library: Option<PathBuf>,
    },
}

pub fn run(args: NewArgs) -> ExitCode {
    let result = match args.what {
        What::Library { name, dir } => library(&name, dir),
        What::Model { file, library } => model(&file, library.as_deref()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

fn library(name: &str, dir: Option<PathBuf>) -> Result<(), String> {
    let valid = is_name(name)
        && name.starts_with(|c: char| c.is_ascii_lowercase())
        && name
            .chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_');
    if !valid {
        return Err(format!(
            "`{}` cannot name a library\n  help: use lowercase letters, digits and `_`, starting with a letter, e.g. `my_robot`",
            crate::bundle::text::comment(name)
        ));
    }
    if let Some(taken) = ferroc_crate(name) {
        return Err(format!(
            "`{name}` is the name of ferroc's own crate `{taken}`: a library of that name \
             would collide with it when a model's program is built\n  help: choose another \
             name, e.g. `my_{name}`"
        ));
    }
    let dir = dir.unwrap_or_else(|| PathBuf::from(name));
    empty_or_new(&dir)?;
    let package = name.replace('_', "-");
    let runtime = crate::runner::source_dir().join("runtime");
    for (file, text) in LIBRARY {
        let file = fill(file, name, &package, &runtime);
        write_new(&dir.join(file), &fill(text, name, &package, &runtime))?;
    }
    one_build_cache(&dir)?;
    let shown = dir.display();
    eprintln!(
        "wrote the library `{name}` in {shown}: Cargo.toml, {name}.lib.xml, src/lib.rs, demo.xml, \
         Cargo.lock, .cargo/config.toml (builds go to the runner cache)\n\
         next:\n  ferroc run {shown}/demo.xml --cycles 5\n  \
         ferroc types export --check --lib-path {shown}\n  \
         (cd {shown} && cargo test)"
    );
    Ok(())
}

/// No second copy of the world for a new library: cargo in its folder (`cargo test`, an
/// editor's rust-analyzer) builds into the runner cache, where `ferroc run` builds its
/// runner, and starts from the checkout's Cargo.lock (the versions ferroc was built
/// and installed with; cargo keeps only those the crate uses).
fn one_build_cache(dir: &Path) -> Result<(), String> {
    let cache = crate::runner::cache::locate();
    let config = format!(
        "# Written by `ferroc new library`: build in ferroc's runner cache (`ferroc cache`),\n\
         # where `ferroc run` builds this library's runner, so both compile it once.\n\
         # CARGO_TARGET_DIR, if set, still wins.\n\
         [build]\ntarget-dir = {}\n",
        toml_str(&cache.dir.to_string_lossy())
    );
    write_new(&dir.join(".cargo/config.toml"), &config)?;
    let lock = crate::runner::source_dir().join("Cargo.lock");
    match std::fs::read_to_string(&lock) {
        Ok(text) => write_new(&dir.join("Cargo.lock"), &text),
        Err(_) => Ok(()), // no checkout lock: cargo resolves the crate's own
    }
}

/// The crates of ferroc's workspace, read from its manifests when ferroc was built
/// (`build.rs`).
const WORKSPACE_CRATES: &[&str] = include!(concat!(env!("OUT_DIR"), "/workspace_crates.rs"));

/// The workspace crate a library called `name` would collide with: the package is
/// `name` with `-` for `_`, its Rust name `name` itself.
fn ferroc_crate(name: &str) -> Option<&'static str> {
    let package = name.replace('_', "-");
    WORKSPACE_CRATES.iter().copied().find(|c| *c == package)
}

fn empty_or_new(dir: &Path) -> Result<(), String> {
    match std::fs::read_dir(dir).map(|mut entries| entries.next().is_some()) {
        Ok(true) => Err(format!(
            "{} exists and is not empty\n  help: choose another folder with --dir",
            dir.display()
        )),
        Ok(_) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(format!("cannot use {}: {e}", dir.display())),
    }
}

/// Writes a file that must not exist yet (never overwrites).
fn write_new(path: &Path, text: &str) -> Result<(), String> {
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent)
            .map_err(|e| format!("cannot create {}: {e}", parent.display()))?;
    }
    use std::io::Write;
    let mut file = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(path)
        .map_err(|e| format!("cannot create {}: {e}", path.display()))?;
    file.write_all(text.as_bytes())
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// The files of a new library, with `@name@`, `@package@` and `@runtime@` to fill in
/// (kept as files so they read, and are reviewed, as what they become).
const LIBRARY: [(&str, &str); 4] = [
    ("Cargo.toml", include_str!("new/library/Cargo.toml.in")),
    ("@name@.lib.xml", include_str!("new/library/NAME.lib.xml")),
    ("src/lib.rs", include_str!("new/library/lib.rs")),
    ("demo.xml", include_str!("new/library/demo.xml")),
];

fn fill(template: &str, name: &str, package: &str, runtime: &Path) -> String {
    template
        .replace("@name@", name)
        .replace("@package@", package)
        .replace("@runtime@", &toml_str(&runtime.to_string_lossy()))
}

/// `ferroc new model FILE`: one part and thread container; with `--library`, one
/// instance of each of its module types, else a standard-library example.
fn model(file: &Path, library: Option<&Path>) -> Result<(), String> {
    let stem = file
        .file_stem()
        .map(|s| s.to_string_lossy().replace(['-', '.', ' '], "_"))
        .unwrap_or_default();
    let app = if is_name(&stem) {
        stem
    } else {
        "app".to_string()
    };
    let mut uses = String::from("  <use library=\"ferroc_std\"/>\n");
    let mut modules = String::new();
    match library {
        Some(manifest) => {
            let (lib, types) = module_types_of(manifest)?;
            let rel = relative_to(file, manifest);
            uses.push_str(&format!(
                "  <use library=\"{}\" manifest=\"{}\"/>\n",
                xml(&lib),
                xml(&rel)
            ));
            for t in &types {
                modules.push_str(&format!(
                    "      <module name=\"{}\" type=\"{}.{}\"/>\n",
                    xml(&t.to_lowercase()),
                    xml(&lib),
                    xml(t)
                ));
            }
            modules.push_str("      <!-- <connect from=\"a/out\" to=\"b/in\"/> -->\n");
        }
        None => modules.push_str(
            "      <module name=\"source\" type=\"ferroc_std.Constant\">\n        <param name=\"value\">1.5</param>\n      </module>\n      <module name=\"double\" type=\"ferroc_std.Scale\">\n        <param name=\"factor\">2</param>\n      </module>\n      <connect from=\"source/value\" to=\"double/input\"/>\n",
        ),
    }
    let text = format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<application name=\"{app}\" version=\"1\">\n{uses}\n  <part name=\"main\" host=\"localhost\">\n    <thread name=\"loop\" period=\"100ms\">\n{modules}    </thread>\n  </part>\n</application>\n"
    );
    if file == Path::new("-") {
        return to_stdout(&text);
    }
    write_new(file, &text)?;
    eprintln!(
        "wrote {}\nnext:\n  ferroc check {}\n  ferroc run {} --cycles 5",
        file.display(),
        file.display(),
        file.display()
    );
    Ok(())
}

/// `ferroc new model -`: the model on standard output (a closed pipe ends it quietly).
fn to_stdout(text: &str) -> Result<(), String> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(format!("cannot write to standard output: {e}"))
        }
        _ => Ok(()),
    }
}

/// The library name and module type names of a manifest `NAME.lib.xml`.
fn module_types_of(manifest: &Path) -> Result<(String, Vec<String>), String> {
    let file = manifest.file_name().unwrap_or_default().to_string_lossy();
    let Some(name) = file.strip_suffix(".lib.xml") else {
        return Err(format!(
            "{}: a library manifest is named NAME.lib.xml",
            manifest.display()
        ));
    };
    let dir = manifest.parent().unwrap_or(Path::new(".")).to_path_buf();
    let options = ferroc_host::loader_options(&[dir], false);
    let loaded = ferroc_compiler::load_manifests(&[name.to_string()], &options);
    let Some(&id) = loaded.libraries.by_name.get(name) else {
        let why = loaded
            .diagnostics
            .first()
            .map(|d| d.message.clone())
            .unwrap_or_else(|| "cannot be read".into());
        return Err(format!("{}: {why}", manifest.display()));
    };
    let lib = loaded.libraries.get(id);
    Ok((
        lib.name.clone(),
        lib.module_types.iter().map(|t| t.name.clone()).collect(),
    ))
}

/// `to` as the model at `from` refers to it (relative when both are relative).
fn relative_to(from: &Path, to: &Path) -> String {
    let base = from.parent().unwrap_or(Path::new(""));
    let (Ok(base), Ok(to_abs)) = (std::path::absolute(base), std::path::absolute(to)) else {
        return to.to_string_lossy().into_owned();
    };
    let b: Vec<_> = base.components().collect();
    let t: Vec<_> = to_abs.components().collect();
    let common = b.iter().zip(&t).take_while(|(x, y)| x == y).count();
    if common <= 1 {
        return to_abs.to_string_lossy().into_owned();
    }
    let mut parts: Vec<String> = vec!["..".into(); b.len() - common];
    parts.extend(
        t[common..]
            .iter()
            .map(|c| c.as_os_str().to_string_lossy().into_owned()),
    );
    parts.join("/")
}
