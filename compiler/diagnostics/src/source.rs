//! Source files and byte spans.
//!
//! Every diagnostic points into a file by byte range; line and column are computed only
//! when a report is rendered, so the parser never pays for them.

use std::path::{Path, PathBuf};

/// Index of a file in a [`SourceMap`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct FileId(pub u32);

/// A byte range in one file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Span {
    pub file: FileId,
    pub start: u32,
    pub end: u32,
}

impl Span {
    pub fn new(file: FileId, start: usize, end: usize) -> Span {
        Span {
            file,
            start: start.min(u32::MAX as usize) as u32,
            end: end.max(start).min(u32::MAX as usize) as u32,
        }
    }

    /// Whether `other` lies inside this span (same file).
    pub fn contains(&self, other: &Span) -> bool {
        self.file == other.file && self.start <= other.start && other.end <= self.end
    }
}

/// One loaded file: its path as the user named it and its text.
pub struct SourceFile {
    /// Path as shown to users (relative paths stay relative).
    pub name: String,
    /// Canonical path, used to detect include cycles and root escapes.
    pub path: PathBuf,
    pub text: String,
    line_starts: Vec<u32>,
    columns: ColumnIndex,
}

/// Bytes per block of a [`ColumnIndex`].
const BLOCK: usize = 256;

/// How many characters and tabs come before each [`BLOCK`]-byte block of a file, so a
/// column is found by counting within one block instead of from the line's start: the
/// places of many findings on one long line (100,000 attributes on one element, a lookup
/// table of 100,000 entries on one line) cost what the findings cost, not the line's
/// length each. Built in the one pass that finds the lines; 8 bytes per block.
#[derive(Debug, Default)]
struct ColumnIndex {
    /// `chars[k]`: characters starting before byte `k * BLOCK`.
    chars: Vec<u32>,
    /// `tabs[k]`: tabs before byte `k * BLOCK`.
    tabs: Vec<u32>,
}

/// Characters starting in `bytes`, and tabs among them.
fn count(bytes: &[u8]) -> (usize, usize) {
    bytes.iter().fold((0, 0), |(chars, tabs), &b| {
        // A UTF-8 continuation byte (10xxxxxx) starts no character.
        (
            chars + usize::from(b & 0xC0 != 0x80),
            tabs + usize::from(b == b'\t'),
        )
    })
}

impl ColumnIndex {
    fn new(text: &str) -> ColumnIndex {
        let mut index = ColumnIndex::default();
        let (mut chars, mut tabs) = (0u32, 0u32);
        for block in text.as_bytes().chunks(BLOCK) {
            index.chars.push(chars);
            index.tabs.push(tabs);
            let (c, t) = count(block);
            chars += c as u32;
            tabs += t as u32;
        }
        index.chars.push(chars);
        index.tabs.push(tabs);
        index
    }

    /// Column of byte `offset` counted from the file's start: a character is one column,
    /// a tab `tab_width`.
    fn column(&self, text: &[u8], offset: usize, tab_width: usize) -> usize {
        let k = offset / BLOCK;
        let (chars, tabs) = count(&text[k * BLOCK..offset]);
        let chars = self.chars[k] as usize + chars;
        let tabs = self.tabs[k] as usize + tabs;
        chars + tabs * tab_width.saturating_sub(1)
    }

    /// The column of block start `k` from the file's start (see [`ColumnIndex::column`]).
    fn block_column(&self, k: usize, tab_width: usize) -> usize {
        self.chars[k] as usize + self.tabs[k] as usize * tab_width.saturating_sub(1)
    }
}

impl SourceFile {
    /// 1-based line and column (in characters) of a byte offset.
    pub fn line_col(&self, offset: u32) -> (usize, usize) {
        let offset = offset.min(self.text.len() as u32);
        let line = match self.line_starts.binary_search(&offset) {
            Ok(i) => i,
            Err(i) => i - 1,
        };
        let start = self.line_starts[line] as usize;
        let mut end = offset as usize;
        while !self.text.is_char_boundary(end) {
            end -= 1;
        }
        (line + 1, self.columns(start, end, 1) + 1)
    }

    /// Columns of `text[from..to]`: a character is one column, a tab `tab_width`. Costs
    /// at most two blocks of counting however long the range.
    pub fn columns(&self, from: usize, to: usize, tab_width: usize) -> usize {
        let bytes = self.text.as_bytes();
        let to = to.min(bytes.len());
        let from = from.min(to);
        self.columns.column(bytes, to, tab_width) - self.columns.column(bytes, from, tab_width)
    }

    /// The offset of the first character of `text[from..end]` that starts at column
    /// `col` or later, columns counted from `from` as [`SourceFile::columns`] does;
    /// `end` when there is none. `from` must be a character boundary.
    pub fn offset_of_column(&self, from: usize, end: usize, col: usize, tab_width: usize) -> usize {
        let bytes = self.text.as_bytes();
        let end = end.min(bytes.len());
        let from = from.min(end);
        let index = &self.columns;
        let target = index.column(bytes, from, tab_width) + col;
        // The last block start in (from, end] whose column is at most the target: the
        // answer lies at or after it (columns only grow).
        let (mut lo, mut hi) = (from / BLOCK + 1, end / BLOCK + 1);
        let first = lo;
        while lo < hi {
            let mid = lo + (hi - lo) / 2;
            if index.block_column(mid, tab_width) <= target {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        let mut pos = if lo > first { (lo - 1) * BLOCK } else { from };
        // A block may start inside a character: that character started before it.
        while pos < end && bytes[pos] & 0xC0 == 0x80 {
            pos += 1;
        }
        let mut at = index.column(bytes, pos, tab_width);
        for (i, c) in self.text[pos..end].char_indices() {
            if at >= target {
                return pos + i;
            }
            at += if c == '\t' { tab_width } else { 1 };
        }
        end
    }

    /// 0-based line of a byte offset (offsets past the end are on the last line).
    pub fn line_of(&self, offset: usize) -> usize {
        let offset = offset.min(self.text.len()) as u32;
        match self.line_starts.binary_search(&offset) {
            Ok(i) => i,
            Err(i) => i - 1,
        }
    }

    /// Number of lines; text after the last newline (even none) is a line.
    pub fn line_count(&self) -> usize {
        self.line_starts.len()
    }

    /// Byte range of a 0-based line without its line break (`\n` or `\r\n`).
    pub fn line_range(&self, line: usize) -> std::ops::Range<usize> {
        let start = self.line_starts[line] as usize;
        let mut end = self
            .line_starts
            .get(line + 1)
            .map_or(self.text.len(), |&next| next as usize - 1);
        if end > start && self.text.as_bytes()[end - 1] == b'\r' && end < self.text.len() {
            end -= 1;
        }
        start..end
    }
}

/// All files of one check run: models, includes, manifests, config files.
#[derive(Default)]
pub struct SourceMap {
    files: Vec<SourceFile>,
}

impl SourceMap {
    pub fn add(&mut self, name: String, path: PathBuf, text: String) -> FileId {
        let mut line_starts = vec![0u32];
        line_starts.extend(
            text.bytes()
                .enumerate()
                .filter(|(_, b)| *b == b'\n')
                .map(|(i, _)| (i + 1) as u32),
        );
        let columns = ColumnIndex::new(&text);
        self.files.push(SourceFile {
            name,
            path,
            text,
            line_starts,
            columns,
        });
        FileId((self.files.len() - 1) as u32)
    }

    pub fn get(&self, id: FileId) -> &SourceFile {
        &self.files[id.0 as usize]
    }

    pub fn find(&self, path: &Path) -> Option<FileId> {
        self.files
            .iter()
            .position(|f| f.path == path)
            .map(|i| FileId(i as u32))
    }

    pub fn files(&self) -> impl Iterator<Item = (FileId, &SourceFile)> {
        self.files
            .iter()
            .enumerate()
            .map(|(i, f)| (FileId(i as u32), f))
    }

    /// `file:line:col` of a span's start.
    pub fn location(&self, span: Span) -> (String, usize, usize) {
        let file = self.get(span.file);
        let (line, col) = file.line_col(span.start);
        (file.name.clone(), line, col)
    }

    /// The text a span covers.
    pub fn text(&self, span: Span) -> &str {
        let text = &self.get(span.file).text;
        text.get(span.start as usize..span.end as usize)
            .unwrap_or("")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_and_column_count_characters() {
        let mut map = SourceMap::default();
        let id = map.add("a.xml".into(), "a.xml".into(), "ab\nüx\n".into());
        let f = map.get(id);
        assert_eq!(f.line_col(0), (1, 1));
        assert_eq!(f.line_col(3), (2, 1));
        // 'x' follows a two-byte character: column 2, not 3.
        assert_eq!(f.line_col(5), (2, 2));
        assert_eq!(f.line_col(99), (3, 1));
    }

    /// Columns as the index gives them equal columns counted character by character, on
    /// lines that cross many blocks, with multi-byte characters on block boundaries and
    /// tabs; `offset_of_column` is their inverse.
    #[test]
    fn the_column_index_counts_as_a_scan_does() {
        let mut text = String::new();
        for i in 0..3000 {
            text.push(match i % 7 {
                0 => 'ü',
                1 => '\t',
                2 => '€',
                3 if i % 500 == 3 => '\n',
                _ => 'a',
            });
        }
        let mut map = SourceMap::default();
        let id = map_add(&mut map, text.clone());
        let f = map.get(id);
        let boundaries: Vec<usize> = (0..=text.len())
            .filter(|&i| text.is_char_boundary(i))
            .collect();
        for tab in [1, 4] {
            for &from in boundaries.iter().step_by(97) {
                // Each character's start offset and column from `from`, by one scan.
                let mut starts = Vec::new();
                let mut col = 0;
                for (i, c) in text[from..].char_indices() {
                    starts.push((from + i, col));
                    col += if c == '\t' { tab } else { 1 };
                }
                starts.push((text.len(), col));
                for &(to, want) in starts.iter().step_by(31) {
                    assert_eq!(f.columns(from, to, tab), want, "{from}..{to}");
                }
                for target in (0..col + 2).step_by(13) {
                    let want = starts
                        .iter()
                        .find(|&&(_, c)| c >= target)
                        .map_or(text.len(), |&(o, _)| o);
                    let at = f.offset_of_column(from, text.len(), target, tab);
                    assert_eq!(at, want, "from {from}, column {target}, tab {tab}");
                }
            }
        }
        for &offset in boundaries.iter().step_by(7) {
            let line = f.line_of(offset);
            let start = f.line_range(line).start;
            let col = text[start..offset].chars().count() + 1;
            assert_eq!(f.line_col(offset as u32), (line + 1, col));
        }
    }

    fn map_add(map: &mut SourceMap, text: String) -> FileId {
        map.add("t".into(), "t".into(), text)
    }
}
