//! A model's text written into another folder (`ferroc inspect --save FILE`): the
//! paths it names relative to its own folder — library manifests (`<use manifest>`),
//! includes (`<include href>`) and config files (`<param config="FILE#/…">`) — are
//! written again relative to the new folder, so the saved model finds the same files.
//!
//! Includes and config files must lie inside the model's folder (the loader's
//! confinement rule, M113): when one would lie outside the new folder the text is
//! refused, saying where it can be saved. A manifest may lie anywhere (named
//! `*.lib.xml`, as the loader requires of one outside the folder). Paths in included
//! fragments are relative to the fragment, which does not move: they stay.

use ferroc_diagnostics::source::FileId;
use ferroc_syntax::escape;
use ferroc_syntax::xml::{self, Element};
use std::path::{Component, Path, PathBuf};

/// `text`, a model in the folder `from`, with its paths made right for the folder
/// `to`; both folders absolute (canonical). An error when the model cannot live in
/// `to` (an include or config file would lie outside it).
pub fn relocate(text: &str, from: &Path, to: &Path) -> Result<String, String> {
    if from == to {
        return Ok(text.to_owned());
    }
    let root = xml::parse(FileId(0), text, 256)
        .map_err(|e| format!("the model is not XML: {}", e.message))?;
    let mut changes = Vec::new();
    collect(&root, from, to, &mut changes)?;
    changes.sort_by_key(|(start, _, _)| std::cmp::Reverse(*start));
    let mut out = text.to_owned();
    for (start, end, value) in changes {
        out.replace_range(start..end, &escape::attr(&value));
    }
    Ok(out)
}

/// (start, end, new value) of every path attribute under `e`.
fn collect(
    e: &Element,
    from: &Path,
    to: &Path,
    out: &mut Vec<(usize, usize, String)>,
) -> Result<(), String> {
    // The attribute and whether its file must lie inside the model's folder.
    let found = match &*e.name {
        "use" => e.attr("manifest").map(|a| (a, false)),
        "include" => e.attr("href").map(|a| (a, true)),
        "param" => e.attr("config").map(|a| (a, true)),
        _ => None,
    };
    if let Some((attr, confined)) = found {
        let (file, pointer) = match attr.value.split_once('#') {
            Some((f, p)) => (f, Some(p)),
            None => (attr.value, None),
        };
        let moved = moved(file, from, to);
        if confined && (moved.starts_with("..") || Path::new(&moved).is_absolute()) {
            return Err(format!(
                "it refers to `{file}` (`<{} {}>`), which must lie inside the model's folder: save it in {} or a folder inside it",
                &*e.name,
                attr.name,
                common_folder(from, &from.join(file)).display()
            ));
        }
        let value = match pointer {
            Some(p) => format!("{moved}#{p}"),
            None => moved,
        };
        let span = attr.value_span;
        out.push((span.start as usize, span.end as usize, value));
    }
    for child in &*e.children {
        collect(child, from, to, out)?;
    }
    Ok(())
}

/// `file` (relative to `from`, or absolute) as the folder `to` names it: relative
/// when both lie on one file system tree, which they do on Unix.
fn moved(file: &str, from: &Path, to: &Path) -> String {
    if Path::new(file).is_absolute() {
        return file.to_owned();
    }
    let target = normalise(&from.join(file));
    relative(&target, to).to_string_lossy().into_owned()
}

/// `path` without `.` and with `..` applied (lexically, as the loader first checks).
fn normalise(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    out
}

/// `target` relative to the folder `base` (both absolute and normalised).
fn relative(target: &Path, base: &Path) -> PathBuf {
    let (t, b): (Vec<_>, Vec<_>) = (target.components().collect(), base.components().collect());
    let common = t.iter().zip(&b).take_while(|(x, y)| x == y).count();
    let mut out = PathBuf::new();
    for _ in common..b.len() {
        out.push("..");
    }
    for c in &t[common..] {
        out.push(c);
    }
    out
}

/// The deepest folder holding both `folder` and `file`'s folder.
fn common_folder(folder: &Path, file: &Path) -> PathBuf {
    let file = normalise(file);
    let parent = file.parent().unwrap_or(Path::new("/"));
    folder
        .ancestors()
        .find(|a| parent.starts_with(a))
        .unwrap_or(Path::new("/"))
        .to_path_buf()
}

#[cfg(test)]
mod tests {
    use super::*;

    const MODEL: &str = r#"<application name="a">
  <use library="ferroc_std"/>
  <use library="extra" manifest="libs/extra.lib.xml"/>
  <part name="robot"><thread name="t" period="1ms">
    <module name="m" type="extra.M"><param name="p" config="cfg/p.xml#/a/b"/></module>
  </thread></part>
</application>
"#;

    #[test]
    fn paths_are_rewritten_for_the_new_folder() {
        let from = Path::new("/work/models");
        assert_eq!(relocate(MODEL, from, from).unwrap(), MODEL);
        // A folder above: the paths go down into the old folder.
        let up = relocate(MODEL, from, Path::new("/work")).unwrap();
        assert!(
            up.contains(r#"manifest="models/libs/extra.lib.xml""#),
            "{up}"
        );
        assert!(up.contains(r#"config="models/cfg/p.xml#/a/b""#), "{up}");
        assert!(up.contains(r#"<use library="ferroc_std"/>"#), "{up}");
        // Elsewhere: the manifest is found from there; the config file would lie
        // outside the folder, which the loader refuses, so the save is refused.
        let e = relocate(MODEL, from, Path::new("/tmp/saved")).unwrap_err();
        assert!(
            e.contains("cfg/p.xml") && e.contains("save it in /work/models"),
            "{e}"
        );
        let no_config = MODEL.replace(r#" config="cfg/p.xml#/a/b""#, "");
        let away = relocate(&no_config, from, Path::new("/tmp/saved")).unwrap();
        assert!(
            away.contains(r#"manifest="../../work/models/libs/extra.lib.xml""#),
            "{away}"
        );
    }
}
