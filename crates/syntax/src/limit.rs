//! Lines, and how many findings of one kind a line keeps.
//!
//! A line ends at `\n`, `\r\n` or a lone `\r`, as the parser, the
//! reports and the language server's positions count lines.
//!
//! A hostile file (a 50 MB line of random letters) has millions of
//! findings; keeping them all costs gigabytes. Reports show at most
//! [`PER_LINE`] findings a line, and what a configuration or an
//! `ncc:ignore` comment turns off is always every finding of a kind (on a
//! line), so a finding that comes after [`PER_LINE`] findings of its own
//! kind on its line is never shown: it is counted ([`Omitted`]) instead of
//! kept.

use std::hash::Hash;

use rowan::TextSize;

/// The most findings a report shows on one line, and so the most of one
/// kind a line keeps.
pub const PER_LINE: usize = 10;

/// Findings of one kind on one line that were counted, not kept.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Omitted<K> {
    pub kind: K,
    /// Where the line starts.
    pub line: TextSize,
    /// Where the first of them starts.
    pub at: TextSize,
    pub count: u32,
}

impl<K> Omitted<K> {
    /// The same findings as another kind (a rule's code for a syntax kind).
    pub fn map<L>(self, kind: impl FnOnce(K) -> L) -> Omitted<L> {
        Omitted { kind: kind(self.kind), line: self.line, at: self.at, count: self.count }
    }

    /// Moved by `offset` (chunk-relative positions become file positions).
    pub fn shifted(mut self, offset: TextSize) -> Self {
        self.line += offset;
        self.at += offset;
        self
    }
}

/// Where the line holding each position starts, for positions that come in
/// order: a pass over a text finds every line in one scan of it.
#[derive(Debug, Clone)]
pub struct LineCursor<'t> {
    bytes: &'t [u8],
    /// The line found last: its start, and where the next one starts
    /// (`None` at the last line).
    start: usize,
    next: Option<usize>,
    /// Nothing found yet.
    fresh: bool,
}

impl<'t> LineCursor<'t> {
    pub fn new(text: &'t str) -> LineCursor<'t> {
        LineCursor { bytes: text.as_bytes(), start: 0, next: None, fresh: true }
    }

    /// The start of the line holding `at`, or `None` when `at` lies before
    /// the line found last (the cursor only moves forward). A position on a
    /// line's terminator belongs to that line.
    pub fn line_start(&mut self, at: usize) -> Option<usize> {
        if self.fresh {
            self.fresh = false;
            self.start = line_start_before(self.bytes, at);
            self.next = next_line_start(self.bytes, self.start);
        }
        if at < self.start {
            return None;
        }
        while let Some(next) = self.next.filter(|&next| at >= next) {
            self.start = next;
            self.next = next_line_start(self.bytes, next);
        }
        Some(self.start)
    }
}

/// Where the line after the one starting at `start` starts, if there is one.
pub fn next_line_start(bytes: &[u8], start: usize) -> Option<usize> {
    let end = start + memchr::memchr2(b'\n', b'\r', bytes.get(start..)?)?;
    Some(if bytes[end] == b'\r' && bytes.get(end + 1) == Some(&b'\n') { end + 2 } else { end + 1 })
}

/// The start of the line holding `at` (the `\n` of a `\r\n` belongs to
/// the line the `\r` ends).
fn line_start_before(bytes: &[u8], at: usize) -> usize {
    let at = at.min(bytes.len());
    let inside_crlf = at > 0 && bytes.get(at) == Some(&b'\n') && bytes[at - 1] == b'\r';
    let search_end = if inside_crlf { at - 1 } else { at };
    memchr::memrchr2(b'\n', b'\r', &bytes[..search_end]).map_or(0, |i| i + 1)
}

/// Decides, for findings that come roughly in order of position, which to
/// keep: the first [`PER_LINE`] of each kind on each line. A finding that
/// starts before one kept earlier on its line is kept (a final
/// [`keep_per_line`] over the sorted list decides), so an order that is
/// only nearly sorted never loses a finding that would be shown.
#[derive(Debug, Clone)]
pub struct LineLimiter<'t, K> {
    cursor: LineCursor<'t>,
    line: Option<usize>,
    /// Per kind on the current line: how many were kept, and the last start.
    seen: Vec<(K, usize, TextSize)>,
    omitted: Vec<Omitted<K>>,
    /// Where the current line's entries in `omitted` begin.
    line_omitted: usize,
}

impl<'t, K: Copy + Eq> LineLimiter<'t, K> {
    pub fn new(text: &'t str) -> Self {
        LineLimiter {
            cursor: LineCursor::new(text),
            line: None,
            seen: Vec::new(),
            omitted: Vec::new(),
            line_omitted: 0,
        }
    }

    /// Whether to keep a finding of `kind` starting at `at`; one not kept
    /// is counted.
    pub fn keep(&mut self, at: TextSize, kind: K) -> bool {
        let Some(line) = self.cursor.line_start(usize::from(at)) else { return true };
        if self.line != Some(line) {
            self.line = Some(line);
            self.seen.clear();
            self.line_omitted = self.omitted.len();
        }
        let seen = match self.seen.iter_mut().find(|(k, ..)| *k == kind) {
            Some(seen) => seen,
            None => {
                self.seen.push((kind, 0, at));
                self.seen.last_mut().expect("just pushed")
            }
        };
        if at < seen.2 {
            return true;
        }
        seen.2 = at;
        if seen.1 < PER_LINE {
            seen.1 += 1;
            return true;
        }
        match self.omitted[self.line_omitted..].iter_mut().find(|o| o.kind == kind) {
            Some(omitted) => omitted.count += 1,
            None => self.omitted.push(Omitted { kind, line: TextSize::from(line as u32), at, count: 1 }),
        }
        false
    }

    /// What was counted, one entry per line and kind, in order of position.
    pub fn finish(self) -> Vec<Omitted<K>> {
        self.omitted
    }
}

/// Keeps the first [`PER_LINE`] findings of each kind on each line of
/// `text` from `items` (sorted by position) and counts the others into
/// `omitted`, which holds what earlier passes over parts of the same
/// lines counted. The result is the same however the findings were split
/// into parts before, as long as each part kept the first ones of its own
/// lines: one entry per line and kind, sorted by position and kind.
pub fn keep_per_line<T, K: Copy + Eq + Ord>(
    text: &str,
    items: Vec<T>,
    omitted: &mut Vec<Omitted<K>>,
    position: impl Fn(&T) -> TextSize,
    kind: impl Fn(&T) -> K,
) -> Vec<T> {
    let mut limiter = LineLimiter::new(text);
    let kept = items.into_iter().filter(|item| limiter.keep(position(item), kind(item))).collect();
    omitted.extend(limiter.finish());
    omitted.sort_by_key(|o| (o.line, o.kind, o.at));
    omitted.dedup_by(|later, first| {
        let same = later.line == first.line && later.kind == first.kind;
        if same {
            first.count += later.count;
        }
        same
    });
    omitted.sort_by_key(|o| (o.at, o.kind));
    kept
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_end_at_lf_crlf_and_lone_cr() {
        let text = "ab\ncd\r\nef\rgh";
        let mut cursor = LineCursor::new(text);
        let starts: Vec<_> = (0..text.len()).map(|at| cursor.line_start(at).unwrap()).collect();
        assert_eq!(starts, [0, 0, 0, 3, 3, 3, 3, 7, 7, 7, 10, 10]);
        assert_eq!(cursor.line_start(2), None, "the cursor only moves forward");
        // Starting on the `\n` of a `\r\n`: the line the `\r` ends.
        assert_eq!(LineCursor::new(text).line_start(6), Some(3));
        assert_eq!(LineCursor::new(text).line_start(text.len()), Some(10));
    }

    #[test]
    fn a_line_keeps_the_first_findings_of_each_kind() {
        let text = format!("{}\n{}", "x".repeat(40), "y".repeat(40));
        let items: Vec<(u32, char)> = (0..30).map(|i| (i, 'a')).chain([(31, 'b'), (41, 'a'), (42, 'a')]).collect();
        let mut omitted = Vec::new();
        let kept = keep_per_line(&text, items, &mut omitted, |&(at, _)| at.into(), |&(_, kind)| kind);
        let expected: Vec<(u32, char)> = (0..10).map(|i| (i, 'a')).chain([(31, 'b'), (41, 'a'), (42, 'a')]).collect();
        assert_eq!(kept, expected);
        assert_eq!(omitted, [Omitted { kind: 'a', line: 0.into(), at: 10.into(), count: 20 }]);
    }

    #[test]
    fn parts_of_a_line_give_what_the_whole_line_gives() {
        let text = "x".repeat(100);
        let items: Vec<(u32, char)> = (0..60).map(|i| (i, if i % 3 == 0 { 'b' } else { 'a' })).collect();
        let mut whole = Vec::new();
        let kept_whole = keep_per_line(&text, items.clone(), &mut whole, |&(at, _)| at.into(), |&(_, k)| k);

        let mut parts = Vec::new();
        let mut kept_parts = Vec::new();
        for part in items.chunks(17) {
            kept_parts.extend(keep_per_line(&text, part.to_vec(), &mut parts, |&(at, _)| at.into(), |&(_, k)| k));
        }
        let kept = keep_per_line(&text, kept_parts, &mut parts, |&(at, _)| at.into(), |&(_, k)| k);
        assert_eq!((kept, parts), (kept_whole, whole));
    }

    #[test]
    fn findings_out_of_order_are_kept() {
        let text = "x".repeat(100);
        let mut limiter = LineLimiter::new(&text);
        for at in 20..30u32 {
            assert!(limiter.keep(at.into(), 'a'));
        }
        assert!(!limiter.keep(30.into(), 'a'));
        assert!(limiter.keep(5.into(), 'a'), "before one kept: a final sorted pass decides");
        assert_eq!(limiter.finish().len(), 1);
    }
}
