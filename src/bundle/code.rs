//! Writing the varying parts of Rust source in rustfmt's layout directly (no rustfmt
//! run); the fixed parts are in the template `templates/main.rs`.

/// rustfmt's default line width and width for one-line lists (`fn_call_width`,
/// `array_width`).
pub(super) const MAX_WIDTH: usize = 100;
pub(super) const LIST_WIDTH: usize = 60;

/// Lines of code at an indentation of four spaces per level.
#[derive(Default)]
pub(super) struct Code {
    pub(super) text: String,
}

impl Code {
    pub(super) fn line(&mut self, indent: usize, text: &str) {
        for l in text.lines() {
            self.text.push_str(&"    ".repeat(indent));
            self.text.push_str(l);
            self.text.push('\n');
        }
    }

    pub(super) fn blank(&mut self) {
        self.text.push('\n');
    }

    /// A `use` list: on one line when it fits, else items filled into lines (rustfmt).
    pub(super) fn fill(&mut self, open: &str, items: &[&str], close: &str) {
        let joined = items.join(", ");
        if open.len() + joined.len() + close.len() <= MAX_WIDTH {
            self.line(0, &format!("{open}{joined}{close}"));
            return;
        }
        self.line(0, open);
        let mut current = String::new();
        for item in items {
            if !current.is_empty() && 4 + current.len() + item.len() + 1 > MAX_WIDTH {
                self.line(1, current.trim_end());
                current.clear();
            }
            current.push_str(item);
            current.push_str(", ");
        }
        self.line(1, current.trim_end_matches(' '));
        self.line(0, close);
    }

    /// `open items close` on one line when it fits (as rustfmt does), else one item a line.
    pub(super) fn list(&mut self, indent: usize, open: &str, items: &[String], close: &str) {
        let joined = items.join(", ");
        if joined.len() <= LIST_WIDTH
            && !joined.contains('\n')
            && indent * 4 + open.len() + joined.len() + close.len() <= MAX_WIDTH
        {
            self.line(indent, &format!("{open}{joined}{close}"));
        } else {
            self.line(indent, open);
            for item in items {
                self.line(indent + 1, &format!("{item},"));
            }
            self.line(indent, close);
        }
    }
}
