//! Code actions from the findings' `help:` lines where the fix is mechanical: "did you
//! mean `x`?" replaces the word the finding points at (a misspelt element, attribute,
//! type, port or library name) and nothing else, so layout and comments stay; the
//! fixes of `fixes.rs` (a connection setting, a missing `<connect>`, …) are sent as
//! the one stretch of text they change.

use crate::convert::Spans;
use crate::navigate::covers;
use crate::request::{self, Reply};
use crate::server::Server;
use ferroc_compiler::diagnostic::{did_you_mean, Diagnostic};
use ferroc_compiler::source::{SourceMap, Span};
use lsp_server::Request;
use lsp_types::{CodeAction, CodeActionKind, CodeActionParams, TextEdit, WorkspaceEdit};
use std::collections::HashMap;

pub fn code_actions(server: &Server, req: &Request) -> Reply {
    let p: CodeActionParams = request::params(req)?;
    let Some(path) = crate::documents::path_of(&p.text_document.uri) else {
        return Ok(Some(serde_json::Value::Null));
    };
    let Some(doc) = server.docs.get(&path) else {
        return Ok(Some(serde_json::Value::Null));
    };
    let start = doc.lines.offset(&doc.text, p.range.start, server.enc);
    let end = doc.lines.offset(&doc.text, p.range.end, server.enc);
    let at = request::At {
        path: path.clone(),
        offset: start,
    };
    let (result, file) = match request::checked(server, &at) {
        Ok(found) => found,
        Err(reply) => return reply,
    };
    let range = Span::new(file, start, end);
    let mut actions = Vec::new();
    let mut spans = Spans::new(&result.sources, server.enc);
    for d in &result.diagnostics {
        let s = d.primary.span;
        let touches = s.file == file && s.start <= range.end && range.start <= s.end;
        if !touches && !covers(s, range) {
            continue;
        }
        let lsp_diagnostic = crate::convert::diagnostic(d, &mut spans);
        let mut action = |title: String, edit: TextEdit, preferred: bool| {
            let changes = HashMap::from([(p.text_document.uri.clone(), vec![edit])]);
            actions.push(CodeAction {
                title,
                kind: Some(CodeActionKind::QUICKFIX),
                diagnostics: Some(vec![lsp_diagnostic.clone()]),
                edit: Some(WorkspaceEdit::new(changes)),
                is_preferred: Some(preferred),
                ..CodeAction::default()
            });
        };
        if let Some(replacement) = suggestion(d, &result.sources) {
            let title = format!(
                "{}: replace `{}` with `{replacement}`",
                d.code(),
                result.sources.text(s)
            );
            action(title, TextEdit::new(spans.range(s), replacement), true);
        }
        for fix in crate::fixes::fixes(d, &result, &doc.text) {
            let (start, end, new) = changed(&doc.text, &fix.text);
            let range = doc.lines.range(&doc.text, start, end, server.enc);
            action(
                fix.title,
                TextEdit::new(range, new.to_string()),
                fix.preferred,
            );
        }
    }
    Ok(Some(serde_json::to_value(actions).unwrap_or_default()))
}

/// The one stretch where `new` differs from `old`: its start and end in `old` and
/// what replaces it (the client's cursor and folds elsewhere stay put).
fn changed<'a>(old: &str, new: &'a str) -> (usize, usize, &'a str) {
    let prefix = (old.char_indices())
        .zip(new.chars())
        .find(|((_, a), b)| a != b)
        .map_or(old.len().min(new.len()), |((i, _), _)| i);
    let (o, n) = (&old[prefix..], &new[prefix..]);
    let suffix = (o.chars().rev())
        .zip(n.chars().rev())
        .take_while(|(a, b)| a == b)
        .map(|(a, _)| a.len_utf8())
        .sum::<usize>();
    (prefix, old.len() - suffix, &new[prefix..new.len() - suffix])
}

/// The replacement a "did you mean `x`?" help offers for the text the finding points
/// at — only when that text is one word close to `x` (the same test the compiler made
/// the suggestion with), so the edit is the one the help means.
pub fn suggestion(d: &Diagnostic, sources: &SourceMap) -> Option<String> {
    let help = d.help.as_deref()?;
    let rest = help.strip_prefix("did you mean ")?;
    let word = if let Some(r) = rest.strip_prefix('`') {
        &r[..r.find('`')?]
    } else if let Some(r) = rest.strip_prefix('<') {
        &r[..r.find('>')?]
    } else {
        return None;
    };
    let written = sources.text(d.primary.span);
    let one_word =
        |w: &str| !w.is_empty() && !w.contains(|c: char| c.is_whitespace() || "<>\"'=".contains(c));
    if !one_word(written) || !one_word(word) || written == word {
        return None;
    }
    did_you_mean(written, [word]).map(str::to_string)
}

#[cfg(test)]
mod tests {
    use super::changed;

    #[test]
    fn the_changed_stretch_is_all_that_is_sent() {
        let old = "<connect from=\"a\" to=\"b\"/> <!-- é -->";
        let new = "<connect from=\"a\" to=\"b\" delay=\"1\"/> <!-- é -->";
        assert_eq!(changed(old, new), (24, 24, " delay=\"1\""));
        // A character that differs in its last byte only is replaced whole.
        assert_eq!(changed("xé", "xè"), (1, 3, "è"));
        assert_eq!(changed("same", "same"), (4, 4, ""));
        assert_eq!(changed("abcabc", "abc"), (3, 6, ""));
    }
}
