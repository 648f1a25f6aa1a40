//! `ferroc import finroc` and `ferroc export finroc`: FINROC applications in and out.

use ferroc_compiler::diagnostic::Diagnostics;
use ferroc_compiler::finroc::{catalogue, checkout::Checkout, import, read, write};
use ferroc_compiler::load::{read_text, Limits};
use ferroc_compiler::source::SourceMap;
use ferroc_compiler::syntax::xml;
use std::path::{Component, Path, PathBuf};
use std::process::ExitCode;

#[derive(clap::Subcommand)]
pub enum ImportFormat {
    /// A FINROC application (.finroc) as a ferroc model, with the catalogue manifests it
    /// uses written beside it
    #[command(
        long_about = "Read a FINROC application (.finroc), the group files and config files \
of its checkout (the nearest folder above holding a make.xml, or --finroc-root), and write a \
ferroc model: the thread container finroc_run makes, a <module> per element whose type the \
catalogue knows, a <group> per composite (what its C++ constructor builds and its group file \
adds), <connect> per edge, <param config cmdline> per parameter link. The catalogue manifests \
the model uses are written next to it. What cannot be imported is listed on stderr.\n\n\
The model is written into the checkout, so that the config files it names lie inside its \
folder (`check` confines them there, M113); written elsewhere, the import says so.\n\n\
Example (in the checkout's folder):\n  ferroc import finroc CrashCourse.finroc -o crash_course.xml\n  \
ferroc check crash_course.xml"
    )]
    Finroc(ImportArgs),
}

#[derive(clap::Args)]
pub struct ImportArgs {
    /// The .finroc file
    input: PathBuf,
    /// The model file to write
    #[arg(short, long)]
    output: PathBuf,
    /// The FINROC checkout the application's group and config files are in
    #[arg(long, value_name = "DIR")]
    finroc_root: Option<PathBuf>,
}

#[derive(clap::Subcommand)]
pub enum ExportFormat {
    /// Write a FINROC application: from a ferroc model (one file per thread container), or
    /// a FINROC file re-written as FINROC's writer does (an unchanged FINROC-written file
    /// comes back byte for byte)
    #[command(long_about = "Write a FINROC application file.\n\n\
From a ferroc model: each thread container is one .finroc file (finroc_run makes one top-level \
thread container per file; the first is written to -o, the others beside it as APP.CONTAINER.finroc). \
Its modules and groups of FINROC catalogue types become elements, its <connect>s edges, \
<param config cmdline> below them parameter links. A model \
made by `ferroc import finroc` keeps FINROC's names and file attributes in `doc`, so it exports \
to the file it came from. From a FINROC application or group file: the file as FINROC's writer \
(SaveXml) writes it.\n\n\
Examples (the first where the import example wrote crash_course.xml):\n  \
ferroc export finroc crash_course.xml -o CrashCourse.finroc\n  \
ferroc export finroc type_conversion.finroc -o -")]
    Finroc(ExportArgs),
}

#[derive(clap::Args)]
pub struct ExportArgs {
    /// A ferroc model, or a FINROC application or group file
    input: PathBuf,
    /// Where to write it (`-` for standard output)
    #[arg(short, long)]
    output: PathBuf,
}

/// Reads a FINROC application or group file, or exports a ferroc model (one file per
/// thread container: its ferroc name and the file); parse problems are printed (short
/// form).
fn read_docs(
    path: &Path,
    sources: &mut SourceMap,
) -> Result<
    Vec<(
        Option<String>,
        ferroc_compiler::finroc::finstructable::Finstructable,
    )>,
    ExitCode,
> {
    let limits = Limits::default();
    let text = read_text(path, &limits).map_err(|e| {
        eprintln!("error: cannot read {}: {e}", path.display());
        ExitCode::from(2)
    })?;
    let file = sources.add(path.display().to_string(), path.to_path_buf(), text);
    let root = xml::parse(file, &sources.get(file).text, limits.max_depth).map_err(|e| {
        let (f, l, c) = sources.location(e.span);
        eprintln!("{f}:{l}:{c}: error[M101]: {}", e.message);
        ExitCode::from(1)
    })?;
    if root.name == "application" {
        // A ferroc model: exported through the catalogue.
        return match ferroc_compiler::finroc::export::export(&root, catalogue::builtin()) {
            Ok(all) => Ok(all
                .into_iter()
                .map(|e| {
                    for n in &e.notes {
                        eprintln!("not exported ({}): {n}", e.container);
                    }
                    (Some(e.container), e.doc)
                })
                .collect()),
            Err(why) => {
                eprintln!("error: {}: {why}", path.display());
                Err(ExitCode::from(1))
            }
        };
    }
    read_doc_of(file, &root, sources).map(|d| vec![(None, d)])
}

/// Reads a FINROC application or group file; parse problems are printed (short form).
fn read_doc(
    path: &Path,
    sources: &mut SourceMap,
) -> Result<ferroc_compiler::finroc::finstructable::Finstructable, ExitCode> {
    let mut docs = read_docs(path, sources)?;
    Ok(docs.remove(0).1)
}

fn read_doc_of(
    file: ferroc_compiler::source::FileId,
    root: &xml::Element,
    sources: &SourceMap,
) -> Result<ferroc_compiler::finroc::finstructable::Finstructable, ExitCode> {
    if !matches!(root.name.as_str(), "Finstructable" | "FinstructableGroup") {
        let (f, l, c) = sources.location(root.name_span);
        eprintln!("{f}:{l}:{c}: error: <{}> is not a FINROC application or group file (root <Finstructable>)", root.name);
        return Err(ExitCode::from(1));
    }
    let mut diags = Diagnostics::default();
    let doc = read::read(file, root, &mut diags);
    for d in &diags.items {
        let (f, l, c) = sources.location(d.primary.span);
        eprintln!(
            "{f}:{l}:{c}: {}[{}]: {}",
            d.severity.as_str(),
            d.code(),
            d.message
        );
    }
    Ok(doc)
}

/// `to` relative to the folder `from` (both made absolute).
fn relative(to: &Path, from: &Path) -> PathBuf {
    let abs = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    let (to, from) = (abs(to), abs(from));
    let t: Vec<Component> = to.components().collect();
    let f: Vec<Component> = from.components().collect();
    let common = t.iter().zip(&f).take_while(|(a, b)| a == b).count();
    let mut out = PathBuf::new();
    for _ in common..f.len() {
        out.push("..");
    }
    for c in &t[common..] {
        out.push(c);
    }
    out
}

pub fn import(format: ImportFormat) -> ExitCode {
    let ImportFormat::Finroc(args) = format;
    let mut sources = SourceMap::default();
    let doc = match read_doc(&args.input, &mut sources) {
        Ok(d) => d,
        Err(code) => return code,
    };
    let root = Checkout::root_of(&args.input, args.finroc_root.as_deref());
    let options = ferroc_compiler::load::Options::default();
    let checkout = Checkout::discover(&root, &args.input, &options, None, &mut sources);
    // `-o model.xml` names no folder: the model goes into the current one.
    let out_dir = match args.output.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    // Config files the model names from outside its folder (`check` refuses them, M113).
    let outside = std::cell::RefCell::new(Vec::<String>::new());
    let config_ref = |c: &ferroc_compiler::finroc::config::ConfigFile| {
        let rel = relative(&sources.get(c.file).path, &out_dir);
        let shown = rel.display().to_string();
        if rel.starts_with("..") || rel.is_absolute() {
            let mut outside = outside.borrow_mut();
            if !outside.contains(&shown) {
                outside.push(shown.clone());
            }
        }
        shown
    };
    let name = doc
        .defaultname
        .as_ref()
        .map(|d| d.text.clone())
        .unwrap_or_else(|| {
            args.input
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default()
        });
    let imported = import::import(&doc, &name, catalogue::builtin(), &checkout, &config_ref);
    if !out_dir.as_os_str().is_empty() {
        if let Err(e) = std::fs::create_dir_all(&out_dir) {
            eprintln!("error: cannot create {}: {e}", out_dir.display());
            return ExitCode::from(2);
        }
    }
    let mut writes = vec![(args.output.clone(), imported.model.clone())];
    for lib in &imported.libraries {
        let file = format!("{lib}.lib.xml");
        if let Some((_, text)) = catalogue::FILES.iter().find(|(n, _)| *n == file) {
            writes.push((out_dir.join(&file), text.to_string()));
        }
    }
    for (path, text) in writes {
        if let Err(e) = std::fs::write(&path, text) {
            eprintln!("error: cannot write {}: {e}", path.display());
            return ExitCode::from(2);
        }
        eprintln!("wrote {}", path.display());
    }
    for n in &imported.notes {
        eprintln!("not imported: {n}");
    }
    warn_outside(&outside.into_inner(), &args.output, &root);
    ExitCode::SUCCESS
}

/// Says at import time what `check` would refuse: config files outside the model's
/// folder (M113), and where to write the model instead so that it checks.
fn warn_outside(outside: &[String], output: &Path, root: &Path) {
    if outside.is_empty() {
        return;
    }
    let name = output.file_name().unwrap_or_default().to_string_lossy();
    eprintln!(
        "warning: the model names config files outside its folder ({}); `ferroc check` keeps \
config files inside the model's folder (M113)\n  help: write the model into the checkout \
(-o {}), or check it with --allow-outside-includes",
        outside.join(", "),
        root.join(&*name).display()
    );
}

pub fn export(format: ExportFormat) -> ExitCode {
    let ExportFormat::Finroc(args) = format;
    let mut sources = SourceMap::default();
    let docs = match read_docs(&args.input, &mut sources) {
        Ok(d) => d,
        Err(code) => return code,
    };
    let to_stdout = args.output == Path::new("-");
    if docs.len() > 1 && to_stdout {
        eprintln!(
            "error: the model has {} thread containers, one .finroc file each: give a file name with -o (the first is written there, the others beside it)",
            docs.len()
        );
        return ExitCode::from(2);
    }
    let mut files = Vec::new();
    for (i, (container, doc)) in docs.iter().enumerate() {
        let path = match (i, container) {
            (0, _) | (_, None) => args.output.clone(),
            (_, Some(c)) => beside(&args.output, c),
        };
        let text = write::write(doc);
        let result = if to_stdout {
            use std::io::Write;
            std::io::stdout().lock().write_all(text.as_bytes())
        } else {
            std::fs::write(&path, text)
        };
        if let Err(e) = result {
            eprintln!("error: cannot write {}: {e}", path.display());
            return ExitCode::from(2);
        }
        files.push(path);
    }
    if files.len() > 1 {
        let list: Vec<String> = files.iter().map(|f| f.display().to_string()).collect();
        eprintln!(
            "wrote {} files, one per thread container; run them together with: finroc_run {}",
            files.len(),
            list.join(" ")
        );
    }
    ExitCode::SUCCESS
}

/// `APP.finroc` and container `vision` → `APP.vision.finroc`.
fn beside(output: &Path, container: &str) -> PathBuf {
    let stem = output
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let stem = stem.strip_suffix(".finroc").unwrap_or(&stem);
    output.with_file_name(format!("{stem}.{container}.finroc"))
}
