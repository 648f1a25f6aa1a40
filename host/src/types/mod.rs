//! `ferroc types`: the module types a binary (ferroc or a runner) registers, and their manifests.
//!
//! A model is checked against manifests; the binary runs Rust types. `list` shows what
//! is built in, `export` writes the manifests the code implies (keeping what only a
//! manifest can say), and `export --check` fails when a checked-in manifest differs
//! from the code, which is how CI keeps the two from drifting apart.

mod manifest_xml;

use crate::interface::differences;
use crate::run::Interfaces;
use ferroc_compiler::diagnostic::Severity;
use ferroc_compiler::report::{self, ModelReport};
use ferroc_runtime::module::Interface;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(clap::Args)]
pub struct TypesArgs {
    #[command(subcommand)]
    command: TypesCommand,
}

impl TypesArgs {
    /// The libraries asked for with `--library` (none: every one found).
    pub fn libraries(&self) -> &[String] {
        match &self.command {
            TypesCommand::List(a) => &a.library,
            TypesCommand::Export(a) => &a.library,
        }
    }

    /// Asks for these libraries, as `--library` does.
    pub fn set_libraries(&mut self, names: Vec<String>) {
        match &mut self.command {
            TypesCommand::List(a) => a.library = names,
            TypesCommand::Export(a) => a.library = names,
        }
    }

    /// The folders searched for manifests (`--lib-path`).
    pub fn lib_path(&self) -> &[PathBuf] {
        match &self.command {
            TypesCommand::List(a) => &a.lib_path,
            TypesCommand::Export(a) => &a.lib_path,
        }
    }
}

#[derive(clap::Subcommand)]
enum TypesCommand {
    /// List the module types of the standard library and of the libraries on the lib path
    #[command(
        long_about = "List the module types of the standard library (built into ferroc) and of every library whose manifest `NAME.lib.xml` is in a --lib-path folder (their crates are built into a runner first, as `ferroc run` does).\n\n\
Examples:\n  ferroc types list\n  ferroc types list --lib-path components"
    )]
    List(ListArgs),
    /// Write library manifests from the module types of their crates
    #[command(
        long_about = "Write `NAME.lib.xml` for every library found on the lib path (and the standard \
library), from the module types its crate registers: the crates are built into a runner \
first, as `ferroc run` does. Ports, parameters, kind, docs and Rust paths come from the code. Everything the \
code cannot say (data types, dependencies, budgets, read modes, services, locks, module types \
without Rust code here) is kept from the existing manifest found on the lib path.\n\n\
With --check nothing is written: each built-in module type is compared with its manifest and \
every difference is listed; the exit code is 1 if there is any. CI runs this so manifests and \
code cannot drift apart.\n\n\
Examples:\n  ferroc types export --check --lib-path components\n  \
ferroc types export --lib-path components -o components\n  \
ferroc types export --library crash_course --lib-path components"
    )]
    Export(ExportArgs),
}

#[derive(clap::Args)]
struct ListArgs {
    /// Only these libraries (repeatable); default: every library on the lib path
    #[arg(long, value_name = "NAME")]
    library: Vec<String>,
    /// Folders searched for `NAME.lib.xml` manifests (also FERROC_LIB_PATH)
    #[arg(long, value_name = "DIR")]
    lib_path: Vec<PathBuf>,
}

#[derive(clap::Args)]
struct ExportArgs {
    /// Only these libraries (repeatable); default: every library on the lib path
    #[arg(long, value_name = "NAME")]
    library: Vec<String>,
    /// Write `NAME.lib.xml` files into this folder (default: stdout, one library only)
    #[arg(short, long, value_name = "DIR")]
    output: Option<PathBuf>,
    /// Compare with the existing manifests instead of writing; exit 1 on any difference
    #[arg(long, conflicts_with = "output")]
    check: bool,
    /// Folders searched for the existing `NAME.lib.xml` manifests (also FERROC_LIB_PATH)
    #[arg(long, value_name = "DIR")]
    lib_path: Vec<PathBuf>,
}

pub fn run(args: TypesArgs, registry: &Interfaces) -> ExitCode {
    match args.command {
        TypesCommand::List(args) => list(args, registry),
        TypesCommand::Export(args) => export(args, registry),
    }
}

/// Built-in interfaces grouped by library, in name order.
fn by_library(registry: &Interfaces) -> BTreeMap<String, Vec<Interface>> {
    let mut out: BTreeMap<String, Vec<Interface>> = BTreeMap::new();
    for (name, i) in registry {
        out.entry(manifest_xml::library_of(name).to_string())
            .or_default()
            .push(i.clone());
    }
    out
}

fn list(args: ListArgs, registry: &Interfaces) -> ExitCode {
    let mut out = String::new();
    for (name, types) in by_library(registry) {
        if !args.library.is_empty() && !args.library.contains(&name) {
            continue;
        }
        for t in types {
            out += &format!(
                "{:<32} {:<14} {} ({}, {})\n",
                t.name,
                t.kind.as_str(),
                t.rust,
                count(t.ports.len(), "port"),
                count(t.params.len(), "parameter")
            );
        }
    }
    crate::output::stdout_then(out.as_bytes(), ExitCode::SUCCESS)
}

/// `1 port`, `2 ports`.
fn count(n: usize, noun: &str) -> String {
    format!("{n} {noun}{}", if n == 1 { "" } else { "s" })
}

fn export(args: ExportArgs, registry: &Interfaces) -> ExitCode {
    let libraries = match selected_libraries(&args, registry) {
        Ok(l) => l,
        Err(code) => return code,
    };
    let names: Vec<String> = libraries.keys().cloned().collect();
    let options = crate::loader_options(&args.lib_path, false);
    let loaded = ferroc_compiler::load_manifests(&names, &options);
    let errors: Vec<_> = loaded
        .diagnostics
        .iter()
        .filter(|d| d.severity == Severity::Error)
        .cloned()
        .collect();
    if args.check {
        return check(&libraries, &loaded, &errors);
    }
    let mut written = Vec::new();
    for (name, types) in &libraries {
        let existing = loaded
            .libraries
            .by_name
            .get(name)
            .map(|&id| (loaded.libraries.get(id), &loaded.sources));
        if existing.is_none() {
            eprintln!(
                "note: no manifest of `{name}` on the lib path; writing one with module types only \
                 (add its data types and dependencies by hand)"
            );
        }
        let rewrite: Vec<&Interface> = types
            .iter()
            .filter(|code| {
                loaded
                    .libraries
                    .module_type(&code.name)
                    .is_none_or(|(_, manifest)| !differences(manifest, code).is_empty())
            })
            .collect();
        let text = manifest_xml::library_xml(name, &rewrite, existing);
        match &args.output {
            None => {
                if let Err(failed) = crate::output::stdout(text.as_bytes()) {
                    return failed;
                }
            }
            Some(dir) => match write_atomically(dir, &format!("{name}.lib.xml"), &text) {
                Ok(written_now) => written.push((written_now, rewrite.len())),
                Err(e) => {
                    eprintln!("error: {e}");
                    return ExitCode::from(2);
                }
            },
        }
    }
    for ((path, changed), rewritten) in written {
        if changed {
            eprintln!(
                "wrote {} ({} generated from code)",
                path.display(),
                count(rewritten, "module type")
            );
        } else {
            eprintln!("unchanged {} (already what the code says)", path.display());
        }
    }
    ExitCode::SUCCESS
}

/// The registered module types of the libraries `--library` picks (all without it),
/// by library; exit code 2 for a library without registered types, or for several
/// libraries to print.
fn selected_libraries(
    args: &ExportArgs,
    registry: &Interfaces,
) -> Result<BTreeMap<String, Vec<Interface>>, ExitCode> {
    let mut libraries = by_library(registry);
    for wanted in &args.library {
        if !libraries.contains_key(wanted) {
            eprintln!(
                "error: --library {wanted}: no module type of this library is registered here\n\
                 help: libraries with registered types: {}",
                libraries.keys().cloned().collect::<Vec<_>>().join(", ")
            );
            return Err(ExitCode::from(2));
        }
    }
    if !args.library.is_empty() {
        libraries.retain(|name, _| args.library.contains(name));
    }
    if !args.check && args.output.is_none() && libraries.len() != 1 {
        eprintln!(
            "error: {} libraries to write and no output folder\n\
             help: add `-o DIR`, or pick one library with `--library NAME` to print it",
            libraries.len()
        );
        return Err(ExitCode::from(2));
    }
    Ok(libraries)
}

/// Lists every difference between a built-in type and its manifest.
fn check(
    libraries: &BTreeMap<String, Vec<Interface>>,
    loaded: &ferroc_compiler::LoadedLibraries,
    errors: &[ferroc_compiler::diagnostic::Diagnostic],
) -> ExitCode {
    let mut failed = !errors.is_empty();
    if failed {
        let mut out = String::new();
        report::short(
            &ModelReport {
                sources: &loaded.sources,
                diagnostics: errors,
            },
            &mut out,
        );
        eprint!("{out}");
    }
    let mut compared = 0;
    for (name, types) in libraries {
        if !loaded.libraries.by_name.contains_key(name) {
            eprintln!(
                "error: no manifest of `{name}` found\n  help: pass the folder holding `{name}.lib.xml` with --lib-path"
            );
            failed = true;
            continue;
        }
        for code in types {
            compared += 1;
            let Some((id, manifest)) = loaded.libraries.module_type(&code.name) else {
                let lib = loaded.libraries.get(loaded.libraries.by_name[name]);
                eprintln!(
                    "{}: error: `{}` is registered by its crate but its manifest does not declare it\n  \
                     help: `ferroc types export --library {name} -o DIR` writes it",
                    loaded.sources.get(lib.file).name,
                    code.name
                );
                failed = true;
                continue;
            };
            let found = differences(manifest, code);
            if !found.is_empty() {
                let file = &loaded.sources.get(loaded.libraries.get(id).file);
                let (line, col) = file.line_col(manifest.span.start);
                eprintln!(
                    "{}:{line}:{col}: error: the manifest of `{}` differs from its Rust type `{}`:",
                    file.name, code.name, code.rust
                );
                for d in found {
                    eprintln!("  - {d}");
                }
                failed = true;
            }
        }
    }
    if failed {
        eprintln!(
            "help: change the code or the manifest; `ferroc types export -o DIR` writes what the code declares"
        );
        ExitCode::from(1)
    } else {
        eprintln!(
            "{} in {} agree with their manifests",
            counted(compared, "module type", "module types"),
            counted(libraries.len(), "library", "libraries")
        );
        ExitCode::SUCCESS
    }
}

/// Writes `dir/name` through a temporary file and a rename, so an interrupted export
/// never leaves a half-written manifest.
/// Writes `dir/name` through a temporary file; `false` when it already held `text`
/// (then it is not touched).
fn write_atomically(dir: &Path, name: &str, text: &str) -> Result<(PathBuf, bool), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let path = dir.join(name);
    if std::fs::read(&path).is_ok_and(|old| old == text.as_bytes()) {
        return Ok((path, false));
    }
    let temporary = dir.join(format!(".{name}.tmp"));
    std::fs::write(&temporary, text)
        .map_err(|e| format!("cannot write {}: {e}", temporary.display()))?;
    std::fs::rename(&temporary, &path).map_err(|e| {
        let _ = std::fs::remove_file(&temporary);
        format!("cannot replace {}: {e}", path.display())
    })?;
    Ok((path, true))
}

/// `1 library`, `3 libraries`: a count as people write it.
fn counted(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}
