//! `ferroc inspect --edit OPS.json` and `--save FILE`: structural edits of a program
//! running with `ferroc run --inspect`, and its model as it runs now (docs/inspect.md,
//! "Structural edits").

use crate::inspect::{emit, Failure};
use ferroc_compiler::diagnostic::escape_controls;
use ferroc_compiler::load::{self, Limits};
use ferroc_inspect::client::Client;
use ferroc_inspect::request::{key, What};
use std::path::Path;

/// An edit file is at most this large (the program refuses larger requests too).
const MAX_EDIT_BYTES: u64 = 64 * 1024;

/// Reads the edit (a JSON list of operations, or `{"ops": [...]}`) from `path` or
/// standard input (`-`).
fn read_ops(path: &Path) -> Result<serde_json::Value, String> {
    let limits = Limits {
        max_file_bytes: MAX_EDIT_BYTES,
        ..Limits::default()
    };
    let text = match load::is_stdin(path) {
        true => load::read_stdin(&limits),
        false => load::read_text(path, &limits),
    }
    .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let json: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| format!("{} is not JSON: {e}", path.display()))?;
    Ok(match json {
        serde_json::Value::Object(mut o) if o.contains_key("ops") => {
            o.remove("ops").unwrap_or_default()
        }
        other => other,
    })
}

/// `--edit`: sends the edit; prints what changed, or the compiler's diagnostics.
pub fn edit(
    client: &Client,
    app: &str,
    path: &Path,
    token: &str,
    json: bool,
) -> Result<(), Failure> {
    let ops = read_ops(path)?;
    let answer = client.edit(app, "*", ops, token)?;
    if json {
        return emit(&format!("{answer}\n"));
    }
    let mut out = String::from("applied:\n");
    let sections = [
        ("edit", "model"),
        ("runtime", "running"),
        ("warnings", "warning"),
    ];
    for (section, prefix) in sections {
        for line in answer[section].as_array().into_iter().flatten() {
            let line = escape_controls(line.as_str().unwrap_or_default());
            out.push_str(&format!("  {prefix}: {line}\n"));
        }
    }
    emit(&out)
}

/// `--save`: writes the model the program runs now to `file` (`-`: standard output).
pub fn save(client: &Client, app: &str, file: &Path) -> Result<(), Failure> {
    let k = key(app, "*", &What::Model);
    let answers = client.ask(&k, None)?;
    let answer = answers.into_iter().next().ok_or_else(|| {
        format!("no program answered `{k}`: is it running with --inspect (and is --app right)?")
    })?;
    let model = answer.result?;
    let text = model["text"]
        .as_str()
        .ok_or_else(|| format!("`{}` answered without a model text", answer.key))?;
    if file == Path::new("-") {
        return emit(text);
    }
    let text = match model["folder"].as_str() {
        Some(folder) => relocated(text, Path::new(folder), file)?,
        None => text.to_owned(),
    };
    std::fs::write(file, text).map_err(|e| format!("cannot write {}: {e}", file.display()))?;
    eprintln!(
        "saved the model of {} to {}",
        model["model"].as_str().unwrap_or("the program"),
        file.display()
    );
    Ok(())
}

/// `text` (the model in `folder`) with its paths written for where `file` lies.
fn relocated(text: &str, folder: &Path, file: &Path) -> Result<String, String> {
    let parent = match file.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let to = std::fs::canonicalize(parent)
        .map_err(|e| format!("cannot write {}: {e}", file.display()))?;
    ferroc_compiler::edit::relocate(text, folder, &to)
        .map_err(|e| format!("the model cannot be saved as {}: {e}", file.display()))
}
