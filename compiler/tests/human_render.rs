//! The human format on hostile text: very long lines, tabs, wide and combining Unicode,
//! control characters, CRLF, spans at line ends and at the end of a file. It must never
//! panic, must show where the finding is, and must not print a line much wider than the
//! terminal or anything that acts on it.

use ferroc_compiler::checks::REGISTRY;
use ferroc_compiler::diagnostic::Diagnostic;
use ferroc_compiler::load::{BuiltinLibrary, Options};
use ferroc_compiler::report::{self, ModelReport};
use ferroc_compiler::source::{FileId, SourceMap, Span};
use ferroc_compiler::{check_model, Policy};
use proptest::prelude::*;
use std::path::Path;

/// The longest line a rendered report may hold, in characters: a clipped source line
/// keeps 80 characters around each label end, a report has at most a few labels.
const MAX_RENDERED_LINE: usize = 1000;

fn render(sources: &SourceMap, diagnostics: &[Diagnostic]) -> String {
    let mut out = String::new();
    report::human::render(
        &ModelReport {
            sources,
            diagnostics,
        },
        false,
        &mut out,
    );
    out
}

/// What every rendering must satisfy; `primaries` are the findings' `file:line:col`.
fn assert_sane(out: &str, primaries: &[String]) {
    assert!(
        !out.contains("Failed to read contents"),
        "a label could not be shown:\n{out}"
    );
    for p in primaries {
        assert!(
            out.contains(&format!("[{p}]")),
            "no snippet headed {p}:\n{out}"
        );
    }
    for line in out.lines() {
        let n = line.chars().count();
        assert!(
            n <= MAX_RENDERED_LINE,
            "a rendered line of {n} characters: {line}"
        );
        assert!(
            !line.chars().any(|c| c.is_control() && c != '\t'),
            "a control character reaches the terminal: {line:?}"
        );
    }
}

fn location(sources: &SourceMap, span: Span) -> String {
    let (f, l, c) = sources.location(span);
    format!("{f}:{l}:{c}")
}

fn options() -> Options {
    Options {
        builtins: vec![BuiltinLibrary {
            name: "ferroc_std".into(),
            text: include_str!("../../components/ferroc_std.lib.xml").into(),
        }],
        ..Options::default()
    }
}

/// The case that made miette panic ("Formatting argument out of range", exit 101): a
/// model line holding a 70,000-character name, with a finding after it on that line.
#[test]
fn a_line_of_70000_characters_is_clipped_around_the_spans() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../models");
    let path = dir.join(format!(".human-render-long-{}.xml", std::process::id()));
    let name = "x-".repeat(35_000);
    let model = format!(
        "<application name=\"a\">\n  <part name=\"p\" host=\"h\">\n    <thread name=\"t\" period=\"10ms\">\n      <module name=\"{name}\" type=\"ferroc_std.Nope\"/>\n    </thread>\n  </part>\n</application>\n"
    );
    std::fs::write(&path, model).unwrap();
    let result = check_model(&path, &options(), &Policy::default());
    let _ = std::fs::remove_file(&path);
    let result = result.unwrap();
    let primaries: Vec<String> = result
        .diagnostics
        .iter()
        .map(|d| location(&result.sources, d.primary.span))
        .collect();
    // The bad name (M107) at its start, the unknown type far to the right of it.
    assert!(
        primaries.iter().any(|p| p.ends_with(":4:21")),
        "{primaries:?}"
    );
    assert!(
        primaries.iter().any(|p| p.ends_with(":4:70029")),
        "{primaries:?}"
    );
    let out = render(&result.sources, &result.diagnostics);
    assert_sane(&out, &primaries);
    // The type's line shows the type and what is around it, with the cut marked.
    assert!(
        out.contains("…x-x-x-x-x-x-x-x-x-x-x-x-x-x-x-x-x-x-x-x-\" type=\"ferroc_std.Nope\"/>"),
        "{out}"
    );
    // The name, quoted in the message, keeps its two ends.
    assert!(out.contains("x-x-x-…"), "{out}");
    assert!(out.len() < 10_000, "{} bytes of report", out.len());
}

/// A line of tabs is short in characters but wide on screen (miette draws a tab as up
/// to four columns): it is clipped by its width, so no rendered line grows past bounds.
#[test]
fn a_line_of_tabs_is_clipped_by_its_width() {
    let mut sources = SourceMap::default();
    let text = format!("<a>\n{}<b/>{}\n</a>\n", "\t".repeat(400), "\t".repeat(400));
    let file = sources.add("t.xml".into(), "t.xml".into(), text.clone());
    let at = text.find("<b/>").unwrap();
    let d = Diagnostic::new(REGISTRY[0], Span::new(file, at, at + 4), "tabs").label("here");
    let out = render(&sources, std::slice::from_ref(&d));
    assert_sane(&out, &["t.xml:2:401".into()]);
    let widest = out.lines().map(|l| l.chars().count()).max().unwrap();
    // 40 columns kept on each side of the span: 20 tabs of 4 columns, plus the frame.
    assert!(
        widest < 250,
        "a rendered line of {widest} characters:\n{out}"
    );
    assert!(out.contains("│ …  "), "the cut is marked:\n{out}");
    assert!(out.contains("<b/>"), "{out}");
}

/// Labels far apart in one file: each shows its own lines, not everything between.
#[test]
fn far_apart_labels_do_not_show_the_lines_between() {
    let mut sources = SourceMap::default();
    let text: String = (1..=200).map(|i| format!("line {i}\n")).collect();
    let file = sources.add("f.xml".into(), "f.xml".into(), text.clone());
    let at = |line: usize| text.find(&format!("line {line}\n")).unwrap();
    let d = Diagnostic::new(REGISTRY[0], Span::new(file, at(150), at(150) + 8), "far")
        .label("here")
        .secondary(Span::new(file, at(10), at(10) + 7), "and there");
    let out = render(&sources, std::slice::from_ref(&d));
    assert_sane(&out, &["f.xml:150:1".into()]);
    for shown in [9, 10, 11, 149, 150, 151] {
        assert!(
            out.contains(&format!("line {shown}\n")),
            "line {shown}:\n{out}"
        );
    }
    for hidden in [8, 12, 100, 148, 152] {
        assert!(
            !out.contains(&format!("line {hidden}\n")),
            "line {hidden}:\n{out}"
        );
    }
}

/// Labels a few lines apart share one snippet, the lines between them shown.
#[test]
fn labels_near_each_other_share_one_snippet() {
    let mut sources = SourceMap::default();
    let text: String = (1..=20).map(|i| format!("line {i}\n")).collect();
    let file = sources.add("f.xml".into(), "f.xml".into(), text.clone());
    let at = |line: usize| text.find(&format!("line {line}\n")).unwrap();
    let d = Diagnostic::new(REGISTRY[0], Span::new(file, at(12), at(12) + 4), "near")
        .label("here")
        .secondary(Span::new(file, at(7), at(7) + 4), "and there");
    let out = render(&sources, std::slice::from_ref(&d));
    assert_sane(&out, &["f.xml:12:1".into()]);
    // One snippet from line 6 to line 13, the lines between included.
    assert_eq!(out.matches("╭─[").count(), 1, "{out}");
    for shown in 6..=13 {
        assert!(
            out.contains(&format!("line {shown}\n")),
            "line {shown}:\n{out}"
        );
    }
}

/// Pieces hostile text is made of.
fn piece() -> impl Strategy<Value = String> {
    prop_oneof![
        "[a-z<>=\" /]{0,12}",
        Just("\t".to_string()),
        Just("漢字".to_string()),
        Just("e\u{301}\u{302}".to_string()),
        Just("🦀".to_string()),
        Just("\u{1b}[31m".to_string()),
        Just("\r".to_string()),
        Just("\u{202e}".to_string()),
        Just("\u{0}\u{7f}\u{85}".to_string()),
        (1usize..3000).prop_map(|n| "a".repeat(n)),
        (30_000usize..40_000).prop_map(|n| "漢".repeat(n)),
        (1usize..400).prop_map(|n| "\t".repeat(n)),
    ]
}

fn file_text() -> impl Strategy<Value = String> {
    let line = prop::collection::vec(piece(), 0..6).prop_map(|p| p.concat());
    (
        prop::collection::vec((line, any::<bool>()), 0..12),
        any::<bool>(),
    )
        .prop_map(|(lines, newline_at_end)| {
            let mut text = String::new();
            for (i, (l, crlf)) in lines.iter().enumerate() {
                text.push_str(l);
                if i + 1 < lines.len() || newline_at_end {
                    text.push_str(if *crlf { "\r\n" } else { "\n" });
                }
            }
            text
        })
}

/// A span: its start is a line start, a line end, the end of the file or anywhere (even
/// inside a character); its length zero, one, some or to the end of the file.
fn span_in(text: &str, pick: (u8, usize, u8, usize)) -> (usize, usize) {
    let ends: Vec<usize> = text.match_indices('\n').map(|(i, _)| i).collect();
    let (kind, n, len_kind, len) = pick;
    let start = match kind % 4 {
        0 => ends
            .get(n % (ends.len() + 1))
            .copied()
            .unwrap_or(text.len()),
        1 => ends.get(n % (ends.len() + 1)).map_or(0, |e| e + 1),
        2 => text.len(),
        _ => n % (text.len() + 1),
    };
    let len = match len_kind % 4 {
        0 => 0,
        1 => 1,
        2 => len % 300,
        _ => text.len() - start,
    };
    (start, (start + len).min(text.len()))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn the_human_format_never_panics_and_stays_bounded(
        a in file_text(),
        b in file_text(),
        labels in prop::collection::vec(
            (any::<bool>(), (any::<u8>(), any::<usize>(), any::<u8>(), any::<usize>())),
            1..5,
        ),
        message in "[a-z `]{1,20}|[a-z]{2000,3000}",
    ) {
        let mut sources = SourceMap::default();
        let fa = sources.add("a.xml".into(), "a.xml".into(), a.clone());
        let fb = sources.add("b.xml".into(), "b.xml".into(), b.clone());
        let span = |in_b: bool, pick| {
            let (file, text): (FileId, &str) = if in_b { (fb, &b) } else { (fa, &a) };
            let (s, e) = span_in(text, pick);
            Span::new(file, s, e)
        };
        let (in_b, pick) = labels[0];
        let mut d = Diagnostic::new(REGISTRY[0], span(in_b, pick), message.clone())
            .label(message.clone())
            .help(message);
        for &(in_b, pick) in &labels[1..] {
            d = d.secondary(span(in_b, pick), "also");
        }
        let primary = location(&sources, d.primary.span);
        let out = render(&sources, std::slice::from_ref(&d));
        assert_sane(&out, &[primary]);
    }
}
