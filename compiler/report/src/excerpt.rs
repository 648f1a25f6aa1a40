//! What the human format shows of a file for one finding: the lines around its labels,
//! long lines clipped around the spans, control characters made visible.
//!
//! miette is handed this excerpt instead of the whole file, for three reasons:
//! - its `SourceCode for &str` scans the file from its start for every label, so a file
//!   with thousands of findings rendered in time quadratic in its size; the excerpt is
//!   found through the file's line index and costs what the snippet costs;
//! - it pads underlines with `{:width$}`, which panics on a line wider than 65,535
//!   columns; clipped lines stay a few hundred columns wide;
//! - it prints lines as they are: a label on a file that is not XML showed every line
//!   between two far-apart labels, and escape sequences reached the terminal.
//!
//! The excerpt is one text made of segments; a segment is a run of consecutive real lines
//! (each label's line range plus the context lines, merged when they are close). `read_span`
//! answers with real line numbers, so miette numbers the lines as in the file, and joins
//! the snippets of labels in one segment and no others.

use ferroc_diagnostics::source::SourceFile;
use miette::{MietteError, MietteSpanContents, SourceCode, SourceSpan, SpanContents};

/// Lines shown above and below a label (miette's default, set on the handler too).
pub(super) const CONTEXT_LINES: usize = 1;
/// Columns of a tab, in miette's rendering (set on the handler) and in our clipping.
pub(super) const TAB_WIDTH: usize = 4;
/// A line wider than this (in columns, a tab counting [`TAB_WIDTH`]) is clipped around
/// its spans.
const MAX_LINE_CHARS: usize = 120;
/// Columns kept on either side of a span's start or end on a clipped line.
const KEEP_AROUND: usize = 40;
/// A multi-line span longer than this shows only its first line.
const MAX_SPAN_LINES: usize = 8;
/// Labels whose shown lines are at most this many lines apart share one snippet (the
/// lines between are shown); farther apart, each gets its own.
const MAX_GAP: usize = 4;
/// Marks what a clipped line leaves out.
const ELLIPSIS: char = '…';

/// One run of consecutive real lines in the excerpt.
#[derive(Debug)]
struct Segment {
    /// 0-based real line of the segment's first line.
    first_line: usize,
    /// Excerpt offsets of each line's start, plus the segment's end.
    starts: Vec<usize>,
}

impl Segment {
    fn end(&self) -> usize {
        *self.starts.last().expect("a segment has an end")
    }
    fn lines(&self) -> usize {
        self.starts.len() - 1
    }
    /// Index (in the segment) of the line holding an excerpt offset.
    fn line_at(&self, offset: usize) -> usize {
        match self.starts.binary_search(&offset) {
            Ok(i) => i.min(self.lines() - 1),
            Err(i) => i - 1,
        }
    }
}

/// The part of one file one finding shows (see the module doc).
#[derive(Debug)]
pub(super) struct Excerpt {
    name: String,
    text: String,
    segments: Vec<Segment>,
    /// Excerpt offset of each label's start with its real 0-based column (in characters,
    /// as the short format counts), for the `[file:line:col]` header.
    starts: Vec<(usize, usize)>,
}

/// A label's byte range in the real file, made safe: inside the text, on character
/// boundaries, a multi-line span cut to its first line when it is long.
fn clamp(file: &SourceFile, start: usize, end: usize) -> (usize, usize) {
    let text = &file.text;
    let floor = |mut i: usize| {
        i = i.min(text.len());
        while !text.is_char_boundary(i) {
            i -= 1;
        }
        i
    };
    let start = floor(start);
    let mut end = floor(end.max(start));
    let first = file.line_of(start);
    if file.line_of(end.saturating_sub(1).max(start)) > first + MAX_SPAN_LINES {
        end = file.line_range(first).end.max(start);
    }
    (start, end)
}

/// The line ranges an excerpt shows: each label's lines with [`CONTEXT_LINES`] around
/// them, sorted, and merged when at most [`MAX_GAP`] lines lie between.
fn line_ranges(file: &SourceFile, labels: &[(usize, usize)]) -> Vec<(usize, usize)> {
    let last_line = file.line_count() - 1;
    let mut ranges: Vec<(usize, usize)> = labels
        .iter()
        .map(|&(s, e)| {
            let (a, b) = (file.line_of(s), file.line_of(e.saturating_sub(1).max(s)));
            (
                a.saturating_sub(CONTEXT_LINES),
                (b + CONTEXT_LINES).min(last_line),
            )
        })
        .collect();
    ranges.sort_unstable();
    let mut merged: Vec<(usize, usize)> = Vec::new();
    for (a, b) in ranges {
        match merged.last_mut() {
            Some(last) if a <= last.1 + 1 + MAX_GAP => last.1 = last.1.max(b),
            _ => merged.push((a, b)),
        }
    }
    merged
}

/// The index range of the (sorted) `points` on `line`, its line break included.
fn points_on_line(file: &SourceFile, points: &[usize], line: usize) -> (usize, usize) {
    let last_line = file.line_count() - 1;
    let range = file.line_range(line);
    let next = if line < last_line {
        file.line_range(line + 1).start
    } else {
        file.text.len()
    };
    let lo = points.partition_point(|&p| p < range.start);
    let hi = points.partition_point(|&p| p <= next);
    let hi = if line < last_line {
        hi.min(points.partition_point(|&p| p < next))
    } else {
        hi
    };
    (lo, hi)
}

impl Excerpt {
    /// The excerpt of `file` for labels given as real byte ranges; returns it with each
    /// label's span in the excerpt, in the same order.
    pub(super) fn new(file: &SourceFile, labels: &[(usize, usize)]) -> (Excerpt, Vec<SourceSpan>) {
        let labels: Vec<(usize, usize)> = labels.iter().map(|&(s, e)| clamp(file, s, e)).collect();
        let last_line = file.line_count() - 1;
        let merged = line_ranges(file, &labels);
        // Every label endpoint, so each line knows what to keep and where it lands.
        let mut points: Vec<usize> = labels.iter().flat_map(|&(s, e)| [s, e]).collect();
        points.sort_unstable();
        points.dedup();
        let mut mapped = vec![0usize; points.len()];
        let mut text = String::new();
        let mut segments = Vec::with_capacity(merged.len());
        for (a, b) in merged {
            let mut starts = Vec::with_capacity(b - a + 2);
            for line in a..=b {
                starts.push(text.len());
                let range = file.line_range(line);
                let (lo, hi) = points_on_line(file, &points, line);
                let base = text.len();
                let line_points = &points[lo..hi];
                let mut at = vec![0usize; line_points.len()];
                write_line(file, range, line_points, &mut at, &mut text);
                // A point inside a `\r\n` break lands at the line's end (`write_line`
                // puts points past the line there): the excerpt writes `\n` alone.
                for (i, _) in line_points.iter().enumerate() {
                    mapped[lo + i] = base + at[i];
                }
                if line < last_line {
                    text.push('\n');
                }
            }
            starts.push(text.len());
            segments.push(Segment {
                first_line: a,
                starts,
            });
        }
        let map = |p: usize| mapped[points.binary_search(&p).expect("every endpoint mapped")];
        let spans = labels
            .iter()
            .map(|&(s, e)| {
                let (vs, ve) = (map(s), map(e).min(text.len()));
                SourceSpan::new(vs.into(), ve.saturating_sub(vs))
            })
            .collect();
        let starts = labels
            .iter()
            .map(|&(s, _)| {
                let (_, col) = file.line_col(s as u32);
                (map(s), col - 1)
            })
            .collect();
        (
            Excerpt {
                name: file.name.clone(),
                text,
                segments,
                starts,
            },
            spans,
        )
    }
}

/// Words (runs without white space) longer than this are shortened in messages.
const MAX_WORD_CHARS: usize = 100;

/// A message, help or label text as the human format shows it: a word longer than
/// [`MAX_WORD_CHARS`] (a 70,000-character name quoted in a message) keeps its two ends
/// around an ellipsis, and control characters are made visible. The other formats keep
/// the full text.
pub(super) fn shorten_words(text: &str) -> String {
    let mut out = String::with_capacity(text.len().min(4096));
    let mut rest = text;
    while !rest.is_empty() {
        let word_len = rest.find(char::is_whitespace).unwrap_or(rest.len());
        let (word, tail) = rest.split_at(word_len);
        let chars = word.chars().count();
        if chars > MAX_WORD_CHARS {
            let keep = MAX_WORD_CHARS / 2 - 1;
            out.extend(word.chars().take(keep).map(visible));
            out.push(ELLIPSIS);
            out.extend(word.chars().skip(chars - keep).map(visible));
        } else {
            out.extend(word.chars().map(visible));
        }
        let space_len = tail
            .find(|c: char| !c.is_whitespace())
            .unwrap_or(tail.len());
        out.extend(tail[..space_len].chars().map(|c| match c {
            '\n' => '\n',
            c => visible(c),
        }));
        rest = &tail[space_len..];
    }
    out
}

/// How a character of the file is shown: control characters and bidirectional overrides
/// would act on the terminal instead of being seen.
fn visible(c: char) -> char {
    match c {
        '\t' => '\t',
        '\u{0}'..='\u{1f}' => char::from_u32(0x2400 + c as u32).unwrap_or('\u{fffd}'),
        '\u{7f}' => '\u{2421}',
        '\u{80}'..='\u{9f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}' => '\u{fffd}',
        c => c,
    }
}

/// Writes one line of `file` (its byte `range`, without the break), clipped around
/// `points` (real offsets, sorted, all on this line or its break) when long; `at[i]`
/// receives where `points[i]` lands, relative to the line's start in `out`.
///
/// Columns come from the file's column index and only the kept parts of a long line are
/// read, so a finding costs what its snippet costs however long the line: a line with
/// 100,000 findings is not read 100,000 times.
fn write_line(
    file: &SourceFile,
    range: std::ops::Range<usize>,
    points: &[usize],
    at: &mut [usize],
    out: &mut String,
) {
    let base = out.len();
    // A tab is counted as wide as miette may draw it, so a line of tabs is clipped like a
    // line of letters.
    let col_of = |p: usize| file.columns(range.start, p.min(range.end), TAB_WIDTH);
    let width = col_of(range.end);
    // Column ranges to keep.
    let keep: Vec<(usize, usize)> = if width <= MAX_LINE_CHARS {
        vec![(0, width)]
    } else {
        let mut keep: Vec<(usize, usize)> = Vec::new();
        let wanted = if points.is_empty() {
            vec![(0, 2 * KEEP_AROUND)]
        } else {
            points
                .iter()
                .map(|&p| {
                    let c = col_of(p);
                    (c.saturating_sub(KEEP_AROUND), (c + KEEP_AROUND).min(width))
                })
                .collect()
        };
        for (a, b) in wanted {
            match keep.last_mut() {
                Some(last) if a <= last.1 => last.1 = last.1.max(b),
                _ => keep.push((a, b)),
            }
        }
        keep
    };
    let mut next_point = 0;
    // Points up to `byte` land where the excerpt is now.
    let mut place = |byte: usize, out: &String, next_point: &mut usize| {
        while *next_point < points.len() && points[*next_point] <= byte {
            at[*next_point] = out.len() - base;
            *next_point += 1;
        }
    };
    // The first character not yet written or skipped.
    let mut cursor = range.start;
    for (a, b) in keep {
        // The characters that start in columns a..b.
        let start = file.offset_of_column(range.start, range.end, a, TAB_WIDTH);
        if start > cursor {
            place(cursor, out, &mut next_point);
            out.push(ELLIPSIS);
        }
        let mut col = col_of(start);
        cursor = start;
        for (i, c) in file.text[start..range.end].char_indices() {
            if col >= b {
                break;
            }
            place(start + i, out, &mut next_point);
            out.push(visible(c));
            col += if c == '\t' { TAB_WIDTH } else { 1 };
            cursor = start + i + c.len_utf8();
        }
    }
    if cursor < range.end {
        place(cursor, out, &mut next_point);
        out.push(ELLIPSIS);
    }
    for slot in &mut at[next_point..] {
        *slot = out.len() - base;
    }
}

impl SourceCode for Excerpt {
    fn read_span<'a>(
        &'a self,
        span: &SourceSpan,
        before: usize,
        after: usize,
    ) -> Result<Box<dyn SpanContents<'a> + 'a>, MietteError> {
        let start = span.offset();
        let end = start + span.len();
        // Segments are back to back: an offset on a boundary starts the next one, unless
        // it is the end of the excerpt.
        let index = self
            .segments
            .partition_point(|s| s.end() <= start)
            .min(self.segments.len().saturating_sub(1));
        let segment = self
            .segments
            .get(index)
            .filter(|s| s.starts[0] <= start && end <= s.end())
            .ok_or(MietteError::OutOfBounds)?;
        let line = segment.line_at(start);
        let first = line.saturating_sub(before);
        let last =
            (segment.line_at(end.saturating_sub(1).max(start)) + after).min(segment.lines() - 1);
        let (from, to) = (segment.starts[first], segment.starts[last + 1]);
        // As miette's own sources: the column only when no lines come before.
        let column = match self.starts.iter().find(|s| s.0 == start) {
            _ if before > 0 => 0,
            Some(&(_, col)) => col,
            None => self
                .text
                .get(segment.starts[line]..start)
                .map_or(0, |t| t.chars().count()),
        };
        Ok(Box::new(MietteSpanContents::new_named(
            self.name.clone(),
            &self.text.as_bytes()[from..to],
            SourceSpan::new(from.into(), to - from),
            segment.first_line + first,
            column,
            // Not the lines returned: miette joins two labels' snippets when one's line
            // plus this count reaches the other's, and labels in one segment share one.
            segment.lines() - first,
        )))
    }
}
