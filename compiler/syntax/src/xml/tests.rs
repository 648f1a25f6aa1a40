use super::*;

fn parse_ok(text: &str) -> Element {
    parse(FileId(0), text, 64).expect("well-formed")
}

#[test]
fn spans_point_at_names_and_values() {
    let text = "<a x=\"1\">\n  <b y='two' />t&amp;u</a>";
    let a = parse_ok(text);
    let x = a.attr("x").unwrap();
    assert_eq!(
        &text[x.name_span.start as usize..x.name_span.end as usize],
        "x"
    );
    assert_eq!(
        &text[x.value_span.start as usize..x.value_span.end as usize],
        "1"
    );
    let b = &a.children[0];
    assert_eq!(
        &text[b.name_span.start as usize..b.name_span.end as usize],
        "b"
    );
    assert_eq!(b.value("y"), Some("two"));
    assert_eq!(a.text().trim(), "t&u");
    assert_eq!(a.span.end as usize, text.len());
}

#[test]
fn malformed_input_is_an_error_with_a_place() {
    for bad in [
        "<a><b></a>",
        "<a",
        "<a x=1/>",
        "",
        "<a/><b/>",
        "<a>&foo;</a>",
        "text",
    ] {
        let err = parse(FileId(0), bad, 64).unwrap_err();
        assert!(!err.message.is_empty(), "{bad}");
        assert!(err.span.start as usize <= bad.len(), "{bad}");
    }
}

/// Attributes and children keep document order; names of the vocabulary and
/// other names (misspelt, or another vocabulary's) read back the same, with their
/// spans, and values with entities keep the span of what the file writes.
#[test]
fn attributes_and_children_read_back_in_order() {
    let text = "<a p=\"1\" from=\"x &amp; y\" perod=\"3\" name='n' Zz-9=\"\">\
                <b x=\"1\"/><c><d/><d/><d/><d/><d/></c><b/><b/><b/><b/></a>";
    let a = parse_ok(text);
    let names = |e: &Element| {
        e.children
            .iter()
            .map(|c| c.name.to_string())
            .collect::<Vec<_>>()
    };
    assert_eq!(names(&a), ["b", "c", "b", "b", "b", "b"]);
    assert_eq!(names(&a.children[1]), ["d"; 5]);
    let attrs: Vec<(&str, &str)> = a.attrs().map(|x| (x.name, x.value)).collect();
    assert_eq!(
        attrs,
        [
            ("p", "1"),
            ("from", "x & y"),
            ("perod", "3"),
            ("name", "n"),
            ("Zz-9", "")
        ]
    );
    for attr in a.attrs() {
        let at = |s: Span| &text[s.start as usize..s.end as usize];
        assert_eq!(at(attr.name_span), attr.name);
        let written = attr.value.replace('&', "&amp;");
        assert_eq!(at(attr.value_span), written, "{}", attr.name);
    }
    assert_eq!(a.value("from"), Some("x & y"));
    assert_eq!(a.value("perod"), Some("3"));
    assert_eq!(a.value("period"), None);
    assert_eq!(a.value("Zz-9"), Some(""));
}

/// The validator's recovery reads a misspelt attribute as the one it was meant to
/// be; the spans stay those of the misspelt name in the file.
#[test]
fn a_renamed_attribute_keeps_its_place() {
    let text = "<thread perod=\"40ms\"/>";
    let mut t = parse_ok(text);
    let before = t.attr("perod").unwrap();
    let (name_span, value_span) = (before.name_span, before.value_span);
    assert!(!t.rename_attr(0, "no-such-attribute"));
    assert!(t.rename_attr(0, "period"));
    assert!(t.attr("perod").is_none());
    let after = t.attr("period").unwrap();
    assert_eq!(after.value, "40ms");
    assert_eq!((after.name_span, after.value_span), (name_span, value_span));
}

/// Text and its span: blanks between child elements are layout, but the blank text
/// of an element without children has its place.
#[test]
fn text_and_its_span() {
    let text = "<a>\n  <p> </p>\n  <q>1 &lt; 2</q><r/>\n</a>";
    let a = parse_ok(text);
    assert_eq!(a.text(), "");
    assert_eq!(a.text_span(), a.span);
    let at = |s: Span| &text[s.start as usize..s.end as usize];
    let (p, q, r) = (&a.children[0], &a.children[1], &a.children[2]);
    assert_eq!((p.text(), at(p.text_span())), ("", " "));
    assert_eq!((q.text(), at(q.text_span())), ("1 < 2", "1 &lt; 2"));
    assert_eq!((r.text(), r.text_span()), ("", r.span));
}

/// The tree's nodes are most of the checker's memory on a large model (B1: ~370,000
/// elements and ~770,000 attributes at 100,000 modules): they must not grow back.
#[test]
fn tree_nodes_stay_small() {
    assert_eq!(std::mem::size_of::<StoredAttr>(), 40);
    assert!(std::mem::size_of::<Element>() <= 80);
}

#[test]
fn an_overlong_attribute_name_is_an_error() {
    let text = format!("<a {}=\"1\"/>", "n".repeat(70_000));
    let err = parse(FileId(0), &text, 64).unwrap_err();
    assert!(err.message.contains("65,535"), "{}", err.message);
    assert_eq!(err.span.start, 3);
}

#[test]
fn depth_is_limited() {
    let text = "<a>".repeat(100) + &"</a>".repeat(100);
    assert!(parse(FileId(0), &text, 50).unwrap_err().too_deep);
    assert!(parse(FileId(0), &text, 200).is_ok());
}

/// `reparse` builds the tree a full parse builds, for edits inside an element, across
/// element boundaries, that break the XML, and that change the file id; and it says
/// the full parse's error when the new text is not XML.
#[test]
fn reparse_equals_a_full_parse() {
    let old = "<?xml version=\"1.0\"?>\n<application name=\"a\">\n  <!-- c -->\n  <part name=\"p\">\n    <thread name=\"t\" period=\"10ms\">\n      <module name=\"m\" type=\"x.Y\"><param name=\"k\">1.5</param></module>\n    </thread>\n  </part>\n  <connect from=\"p/t/m/out\" to=\"p/t/m/in\"/>\n</application>\n";
    let edits: &[(&str, &str)] = &[
        ("name=\"m\"", "name=\"mm\""),
        ("name=\"m\"", "name=\"\""),
        ("1.5", "2.75 m"),
        ("period=\"10ms\"", "period=\"10ms\" cpu=\"1\""),
        ("<module", "<module x=\"&amp;\""),
        (
            "</module>",
            "</module>\n      <module name=\"n\" type=\"x.Y\"/>",
        ),
        ("<part name=\"p\">", "<part name=\"q\">"),
        ("name=\"a\"", "name=\"ab\""),
        ("<!-- c -->", "<!-- cc -->"),
        ("p/t/m/in", "p/t/m/i"),
        ("</thread>", "</thread><thread name=\"u\"/>"),
        ("<param name=\"k\">1.5</param>", ""),
        ("</module>", "</modul>"),
        ("1.5", "1 < 2"),
        ("<thread", "<thread <"),
        ("\"x.Y\">", "\"x.Y\"/>"),
        ("<application name=\"a\"", "<application name=\"a>b\" v='1'"),
        ("<application name", "<applicatio name"),
        ("<part name=\"p\"", "<part name=\"p\"/"),
        ("<part name=\"p\"", "<part name=\"p\">x</part><part"),
        ("<part name=\"p\"", "<part name=\"p"),
        ("<module name=\"m\"", "<module name=\"m&lt;\""),
        ("<module name=\"m\"", "<module name=\"m&nope;\""),
        ("<thread name=\"t\"", "<thread name=\"t\" a=\"1\" a=\"2\""),
    ];
    for (from, to) in edits {
        let new = old.replacen(from, to, 1);
        let mut tree = parse(FileId(3), old, 64).unwrap();
        let got = reparse(&mut tree, old, &new, FileId(5), 64).map(|()| tree);
        let want = parse(FileId(5), &new, 64);
        match (got, want) {
            (Ok(g), Ok(w)) => assert_eq!(format!("{g:?}"), format!("{w:?}"), "{from} → {to}"),
            (Err(g), Err(w)) => assert_eq!((g.span, g.message), (w.span, w.message)),
            (g, w) => panic!("{from} → {to}: {:?} vs {:?}", g.is_ok(), w.is_ok()),
        }
    }
    // Depth is counted from the document's root, not from the element parsed again.
    let deep = "<a><b><c></c></b></a>";
    let deeper = "<a><b><c><d/></c></b></a>";
    let mut tree = parse(FileId(0), deep, 4).unwrap();
    assert!(reparse(&mut tree, deep, deeper, FileId(0), 3).is_err_and(|e| e.too_deep));
}

proptest::proptest! {
    /// Random edits of a model (a range replaced by random XML-ish text): `reparse`
    /// of the old tree and a full parse of the new text agree, tree or error.
    #[test]
    fn reparse_agrees_with_parse_on_random_edits(
        at in 0usize..400,
        len in 0usize..12,
        with in "[<>/=\"' a-z&;]{0,12}",
    ) {
        let old = "<application name=\"a\" version=\"1\">\n  <part name=\"p\">\n    <thread name=\"t\" period=\"10ms\">\n      <module name=\"m\" type=\"x.Y\"><param name=\"k\">1.5</param></module>\n      <module name=\"n\" type=\"x.Y\"/>\n    </thread>\n  </part>\n  <connect from=\"p/t/m/out\" to=\"p/t/n/in\" on-full=\"block\"/>\n</application>\n";
        let at = at.min(old.len());
        let end = (at + len).min(old.len());
        let new = format!("{}{}{}", &old[..at], with, &old[end..]);
        let mut tree = parse(FileId(1), old, 8).unwrap();
        let got = reparse(&mut tree, old, &new, FileId(2), 8).map(|()| tree);
        let want = parse(FileId(2), &new, 8);
        match (got, want) {
            (Ok(g), Ok(w)) => proptest::prop_assert_eq!(format!("{g:?}"), format!("{w:?}")),
            (Err(g), Err(w)) => proptest::prop_assert_eq!((g.span, g.message), (w.span, w.message)),
            (g, w) => proptest::prop_assert!(false, "{} vs {}", g.is_ok(), w.is_ok()),
        }
    }
}
