//! The control's tables: zero offsets (TAB0.POS) and tool corrections
//! (TAB0.KOR), and readers for both files.
//!
//! Values are kept as integer thousandths: µm for linear axes, thousandths
//! of a degree for rotary ones, so a table can be compared and hashed.
//!
//! **TAB0.KOR** (02 §1.3, 000:2201-2251): any comment, then a line `$KOR`,
//! then one line per correction:
//!
//! ```text
//! $KOR
//! 01: R=10.0 X=20.0 Y=30.0 Z=40.0
//! 02: R=0.8 X=0.0 2=0.0 P=3
//! ```
//!
//! The entry number (01-99) and a colon, then the radius `R=`, lengths per
//! axis, and on lathes the tool's tip position `P=` (1-9). An axis is
//! written by its ordinal digit or by its name, and the names stand for
//! fixed positions (X = 1, Y = 2, Z = 3, U = 4): they are right only on a
//! machine whose axes come in that order, so a lathe's Z is `2=`
//! (000:2206-2212). Whatever the file does not give is zero (000:2219-2224).
//!
//! **TAB0.POS**: the manual names the file and says the control loads it
//! at power-on and when it is saved (000:1157, 1299-1305), but does not
//! print its syntax. This reader assumes the layout of TAB0.KOR, with the
//! rows of the offset table (01 §5.5) as entries and the machine's axis
//! letters or ordinal digits as keys:
//!
//! ```text
//! $POS
//! G54: X=100.5 Y=-20.0 Z=0.0
//! G55: 1=30.0 2=10.0
//! ```
//!
//! In both files the manual writes every value with a decimal point and
//! never says how one without it reads; it is read in millimetres (or
//! degrees), as a coordinate is (`X100` is 100 mm, 01 §5.2). A value is
//! given to the µm at most. A line the reader does not understand becomes
//! a [`Finding`] at its line and column; the rest of the file is still
//! read.

use std::{collections::BTreeMap, fmt};

use crate::machine::{OffsetTable, ToolTable, signed_decimal};

/// A problem in a table file, at a line and a column (both from 1).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Finding {
    pub line: u32,
    pub column: u32,
    pub message: String,
}

impl fmt::Display for Finding {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}: {}", self.line, self.column, self.message)
    }
}

/// The largest coordinate, ±69999.999 in thousandths (the `+5.3` format,
/// 000:171).
const COORDINATE_LIMIT: i32 = 69_999_999;

/// The largest length correction, ±999.999 mm (000:3122-3123).
const LENGTH_LIMIT: i32 = 999_999;

impl OffsetTable {
    /// Reads a TAB0.POS file for a machine with the axes `axes`.
    pub fn parse(text: &str, axes: &[u8]) -> (OffsetTable, Vec<Finding>) {
        let mut table = OffsetTable::default();
        let mut findings = Vec::new();
        let mut first_lines = BTreeMap::new();
        for entry in entries(text, "$POS", &mut findings) {
            let code = entry
                .label
                .strip_prefix(['G', 'g'])
                .and_then(|code| code.parse().ok())
                .filter(|code| (53..=59).contains(code) && entry.label.len() == 3);
            let Some(code) = code else {
                findings.push(entry.at_label(format!("`{}` names no row: the rows are G53 to G59", entry.label)));
                continue;
            };
            entry.check_repeated(code, &mut first_lines, &mut findings);
            let row = table.rows.entry(code).or_default();
            let mut given = [false; 6];
            for item in &entry.items {
                let Some(axis) = position_axis(item.key, axes) else {
                    let message = format!("`{}` is not an axis of this machine ({})", item.key, axis_list(axes));
                    findings.push(entry.at(item.at, message));
                    continue;
                };
                if !item.once(&mut given[axis], &entry, &mut findings) {
                    continue;
                }
                match coordinate(item.value) {
                    Ok(value) => row[axis] = value,
                    Err(message) => findings.push(entry.at(item.value_at(), message)),
                }
            }
        }
        (table, in_file_order(findings))
    }
}

impl ToolTable {
    /// Reads a TAB0.KOR file for a machine with the axes `axes` (they
    /// decide where an axis name may be written).
    pub fn parse(text: &str, axes: &[u8]) -> (ToolTable, Vec<Finding>) {
        let mut table = ToolTable::default();
        let mut findings = Vec::new();
        let mut first_lines = BTreeMap::new();
        for entry in entries(text, "$KOR", &mut findings) {
            let number = Some(entry.label)
                .filter(|label| (1..=2).contains(&label.len()) && label.bytes().all(|b| b.is_ascii_digit()))
                .and_then(|label| label.parse().ok())
                .filter(|number| (1..=99).contains(number));
            let Some(number) = number else {
                let message = format!("`{}` is no correction number: write two digits, 01 to 99", entry.label);
                findings.push(entry.at_label(message));
                continue;
            };
            entry.check_repeated(number, &mut first_lines, &mut findings);
            let tool = table.entries.entry(number).or_default();
            let mut given = [false; 8];
            for item in &entry.items {
                let key = match item.key.as_bytes() {
                    [b'R' | b'r'] => Ok(Datum::Radius),
                    [b'P' | b'p'] => Ok(Datum::Tip),
                    _ => correction_axis(item.key, axes).map(Datum::Length),
                };
                let key = match key {
                    Ok(key) => key,
                    Err(message) => {
                        findings.push(entry.at(item.at, message));
                        continue;
                    }
                };
                let slot = match key {
                    Datum::Radius => 0,
                    Datum::Tip => 1,
                    Datum::Length(axis) => axis + 2,
                };
                if !item.once(&mut given[slot], &entry, &mut findings) {
                    continue;
                }
                let read = match key {
                    Datum::Radius => coordinate(item.value).map(|radius| tool.radius = radius),
                    Datum::Tip => tip(item.value).map(|tip| tool.tip = Some(tip)),
                    Datum::Length(axis) => {
                        thousandths(item.value, LENGTH_LIMIT).map(|length| tool.lengths[axis] = length)
                    }
                };
                if let Err(message) = read {
                    findings.push(entry.at(item.value_at(), message));
                }
            }
        }
        (table, in_file_order(findings))
    }
}

/// What an item of a TAB0.KOR entry sets.
#[derive(Clone, Copy)]
enum Datum {
    Radius,
    Tip,
    /// The length correction of an axis (0-5).
    Length(usize),
}

/// An entry line: `label: key=value key=value …`.
struct Entry<'a> {
    line: u32,
    text: &'a str,
    label: &'a str,
    /// Byte offset of the label in the line.
    label_at: usize,
    items: Vec<Item<'a>>,
}

struct Item<'a> {
    key: &'a str,
    value: &'a str,
    /// Byte offset of the key in the line.
    at: usize,
}

impl Item<'_> {
    fn value_at(&self) -> usize {
        self.at + self.key.len() + 1
    }

    /// Marks the item's key as given; false, after a finding, when the line
    /// gave it before.
    fn once(&self, given: &mut bool, entry: &Entry<'_>, findings: &mut Vec<Finding>) -> bool {
        if std::mem::replace(given, true) {
            findings.push(entry.at(self.at, format!("`{}` is given twice in this line", self.key)));
            return false;
        }
        true
    }
}

impl Entry<'_> {
    /// A finding at byte offset `at` of the line.
    fn at(&self, at: usize, message: String) -> Finding {
        let column = self.text[..at].chars().count() + 1;
        Finding { line: self.line, column: u32::try_from(column).unwrap_or(u32::MAX), message }
    }

    fn at_label(&self, message: String) -> Finding {
        self.at(self.label_at, message)
    }

    /// Reports an entry that an earlier line gave already; the later line's
    /// values win, as they would if the control read the file top down.
    fn check_repeated(&self, key: u8, first_lines: &mut BTreeMap<u8, u32>, findings: &mut Vec<Finding>) {
        match first_lines.get(&key) {
            Some(first) => {
                findings.push(self.at_label(format!("`{}` is given again (first in line {first})", self.label)))
            }
            None => {
                first_lines.insert(key, self.line);
            }
        }
    }
}

/// The entry lines of a table file: those after the `keyword` line (what
/// precedes it is comment), blank lines left out. Lines without the label's
/// colon and items without `=` become findings.
fn entries<'a>(text: &'a str, keyword: &str, findings: &mut Vec<Finding>) -> Vec<Entry<'a>> {
    let mut lines = (1..).zip(text.lines());
    if !lines.any(|(_, line)| line.trim() == keyword) {
        findings.push(Finding {
            line: 1,
            column: 1,
            message: format!("no `{keyword}` line: the table starts after it"),
        });
        return Vec::new();
    }
    let mut entries = Vec::new();
    for (line, text) in lines.filter(|(_, text)| !text.trim().is_empty()) {
        let label_at = text.len() - text.trim_start().len();
        let Some((label, rest)) = text.split_once(':') else {
            let entry = Entry { line, text, label: text.trim(), label_at, items: Vec::new() };
            findings.push(entry.at_label("expected an entry: its label, a colon and `key=value` items".to_owned()));
            continue;
        };
        let mut entry = Entry { line, text, label: label.trim(), label_at, items: Vec::new() };
        // Words and their offsets in the line; the separators are one byte.
        let words = rest.split([' ', '\t', '\r']).scan(label.len() + 1, |at, word| {
            let start = *at;
            *at += word.len() + 1;
            Some((start, word))
        });
        for (at, word) in words.filter(|(_, word)| !word.is_empty()) {
            match word.split_once('=') {
                Some((key, value)) if !key.is_empty() => entry.items.push(Item { key, value, at }),
                _ => findings.push(entry.at(at, format!("expected `key=value`, found `{word}`"))),
            }
        }
        entries.push(entry);
    }
    entries
}

/// Findings in file order: splitting the lines reports some, reading the
/// entries the others.
fn in_file_order(mut findings: Vec<Finding>) -> Vec<Finding> {
    findings.sort_by_key(|finding| (finding.line, finding.column));
    findings
}

/// An axis of TAB0.POS: one of the machine's letters or an ordinal digit.
fn position_axis(key: &str, axes: &[u8]) -> Option<usize> {
    match *key.as_bytes() {
        [digit @ b'1'..=b'6'] => Some(usize::from(digit - b'1')).filter(|&axis| axis < axes.len()),
        [letter] => axes.iter().position(|&axis| axis == letter.to_ascii_uppercase()),
        _ => None,
    }
}

/// An axis of TAB0.KOR: an ordinal digit, or a name standing for a fixed
/// position (000:2206-2212). Axes 5 and 6 are read as `5=` and `6=`: the
/// control corrects their lengths from panel 30.29 on (000:3070-3071), but
/// the manual shows no file line for them.
fn correction_axis(key: &str, axes: &[u8]) -> Result<usize, String> {
    const NAMES: &[u8] = b"XYZU";
    match *key.as_bytes() {
        [digit @ b'1'..=b'6'] => Ok(usize::from(digit - b'1')),
        [letter] if NAMES.contains(&letter.to_ascii_uppercase()) => {
            let letter = letter.to_ascii_uppercase();
            let axis = NAMES.iter().position(|&name| name == letter).unwrap_or_default();
            if axes.get(axis) == Some(&letter) {
                return Ok(axis);
            }
            let instead = match axes.iter().position(|&a| a == letter) {
                Some(actual) => {
                    format!("on this machine {} is axis {}: write `{}=`", char::from(letter), actual + 1, actual + 1)
                }
                None => format!("this machine has no {} axis ({})", char::from(letter), axis_list(axes)),
            };
            Err(format!(
                "`{key}=` corrects axis {} (the names stand for X, Y, Z, U in that order), but {instead}",
                axis + 1
            ))
        }
        _ => Err(format!("`{key}` is neither R, P, an axis digit 1-6 nor X, Y, Z, U")),
    }
}

/// The axis letters for a message: `axes X Y Z`.
pub fn axis_list(axes: &[u8]) -> String {
    let letters: Vec<String> = axes.iter().map(|&axis| char::from(axis).to_string()).collect();
    format!("axes {}", letters.join(" "))
}

/// A coordinate in mm (or degrees) as integer thousandths, written as in the
/// table files.
pub fn coordinate(text: &str) -> Result<i32, String> {
    thousandths(text, COORDINATE_LIMIT)
}

/// A value in mm (or degrees) as integer thousandths, within ±`limit`.
fn thousandths(text: &str, limit: i32) -> Result<i32, String> {
    if text.is_empty() {
        return Err("the value after `=` is missing".to_owned());
    }
    let value = signed_decimal(text).ok_or_else(|| format!("`{text}` is not a number"))?;
    let thousandths = value.scaled(3).ok_or_else(|| format!("`{text}` is finer than the control's 0.001"))?;
    i32::try_from(thousandths)
        .ok()
        .filter(|value| value.abs() <= limit)
        .ok_or_else(|| format!("`{text}` is outside ±{}.{:03}", limit / 1000, limit % 1000))
}

/// The tip position `P`: one digit 1-9 (000:2250).
fn tip(text: &str) -> Result<u8, String> {
    match *text.as_bytes() {
        [digit @ b'1'..=b'9'] => Ok(digit - b'0'),
        _ => Err(format!("`P={text}`: the tip position is one of 1 to 9")),
    }
}

#[cfg(test)]
mod tests {
    use expect_test::{Expect, expect};

    use super::*;
    use crate::machine::ToolEntry;

    const MILL: &[u8] = b"XYZ";
    const LATHE: &[u8] = b"XZ";

    fn render<T: fmt::Debug>(rows: impl Iterator<Item = (u8, T)>, findings: &[Finding], label: &str) -> String {
        let rows = rows.map(|(key, row)| format!("{label}{key:02}: {row:?}\n"));
        let findings = findings.iter().map(|finding| format!("{finding}\n"));
        rows.chain(findings).collect()
    }

    fn check_offsets(text: &str, axes: &[u8], expect: Expect) {
        let (table, findings) = OffsetTable::parse(text, axes);
        expect.assert_eq(&render(table.rows.into_iter(), &findings, "G"));
    }

    fn check_tools(text: &str, axes: &[u8], expect: Expect) {
        let (table, findings) = ToolTable::parse(text, axes);
        expect.assert_eq(&render(table.entries.into_iter(), &findings, "D"));
    }

    #[test]
    fn reads_the_manuals_correction_file() {
        // 000:2227-2232, on a four-axis mill.
        check_tools(
            "Tools of machine 3\n$KOR      \n01: R=10.0 X=20.0 Y=30.0 Z=40.0  \n02: R=0.8 X=0.0 2=0.0   \n03: R=0.8 X=0.0 Y=120.0 Z=0.0 4=0.0 \n25:  X=85.0 Y=45.5 Z=0.0  \n95: R=0.0 1=12.55 2=0.0 3=0.0 4=0.0 \n",
            b"XYZU",
            expect![[r#"
                D01: ToolEntry { radius: 10000, lengths: [20000, 30000, 40000, 0, 0, 0], tip: None }
                D02: ToolEntry { radius: 800, lengths: [0, 0, 0, 0, 0, 0], tip: None }
                D03: ToolEntry { radius: 800, lengths: [0, 120000, 0, 0, 0, 0], tip: None }
                D25: ToolEntry { radius: 0, lengths: [85000, 45500, 0, 0, 0, 0], tip: None }
                D95: ToolEntry { radius: 0, lengths: [12550, 0, 0, 0, 0, 0], tip: None }
            "#]],
        );
    }

    #[test]
    fn reads_a_lathe_entry_with_its_tip() {
        // 000:2612-2613, with CR LF line ends; entry 7 has no radius.
        let (table, findings) =
            ToolTable::parse("$KOR\r\n01:  R=0.8   X=120.0   2=340.5     P=3\r\n7: 2=-1\r\n", LATHE);
        assert_eq!(findings, []);
        assert_eq!(table.entry(1), ToolEntry { radius: 800, lengths: [120_000, 340_500, 0, 0, 0, 0], tip: Some(3) });
        assert_eq!(table.entry(7).lengths[1], -1000, "without a point in mm");
        assert_eq!(table.entry(50), ToolEntry::default());
    }

    #[test]
    fn reports_every_kind_of_bad_correction_line() {
        check_tools(
            "$KOR\n01: R=1.0 Z=5.0\n100: R=1.0\nxx\n02: R=abc X=1.0001 2=1000.0 P=0\n03: R=1 R=2 W=1 7=0 U=1 2\n01: R=3.0\n",
            LATHE,
            expect![[r#"
                D01: ToolEntry { radius: 3000, lengths: [0, 0, 0, 0, 0, 0], tip: None }
                D02: ToolEntry { radius: 0, lengths: [0, 0, 0, 0, 0, 0], tip: None }
                D03: ToolEntry { radius: 1000, lengths: [0, 0, 0, 0, 0, 0], tip: None }
                2:11: `Z=` corrects axis 3 (the names stand for X, Y, Z, U in that order), but on this machine Z is axis 2: write `2=`
                3:1: `100` is no correction number: write two digits, 01 to 99
                4:1: expected an entry: its label, a colon and `key=value` items
                5:7: `abc` is not a number
                5:13: `1.0001` is finer than the control's 0.001
                5:22: `1000.0` is outside ±999.999
                5:31: `P=0`: the tip position is one of 1 to 9
                6:9: `R` is given twice in this line
                6:13: `W` is neither R, P, an axis digit 1-6 nor X, Y, Z, U
                6:17: `7` is neither R, P, an axis digit 1-6 nor X, Y, Z, U
                6:21: `U=` corrects axis 4 (the names stand for X, Y, Z, U in that order), but this machine has no U axis (axes X Z)
                6:25: expected `key=value`, found `2`
                7:1: `01` is given again (first in line 2)
            "#]],
        );
    }

    #[test]
    fn a_file_without_its_keyword_is_one_finding() {
        check_tools("01: R=1.0\n", MILL, expect!["1:1: no `$KOR` line: the table starts after it\n"]);
        check_offsets("", MILL, expect!["1:1: no `$POS` line: the table starts after it\n"]);
    }

    #[test]
    fn reads_an_offset_file() {
        check_offsets(
            "Offsets of the mill\n$POS\n\nG54: X=100.5 Y=-20 Z=-300.650\ng55: 1=30.0 2=+10.0\nG59: z=0.001\n",
            MILL,
            expect![[r#"
                G54: [100500, -20000, -300650, 0, 0, 0]
                G55: [30000, 10000, 0, 0, 0, 0]
                G59: [0, 0, 1, 0, 0, 0]
            "#]],
        );
        let (table, _) = OffsetTable::parse("$POS\nG54: X=1.0\n", MILL);
        assert_eq!(table.offset(54)[0], 1000);
        assert_eq!(table.offset(53), [0; 6]);
    }

    #[test]
    fn reports_every_kind_of_bad_offset_line() {
        check_offsets(
            "$POS\nG60: X=1.0\nG5: X=1.0\nG54 X=1.0\nG54: U=1.0 4=1.0 X=1.0 1=2.0 Y=\nG55: Z=70000.0 Y=1.2.3 X-1.0\nG54: Z=1.0\n",
            MILL,
            expect![[r#"
                G54: [1000, 0, 1000, 0, 0, 0]
                G55: [0, 0, 0, 0, 0, 0]
                2:1: `G60` names no row: the rows are G53 to G59
                3:1: `G5` names no row: the rows are G53 to G59
                4:1: expected an entry: its label, a colon and `key=value` items
                5:6: `U` is not an axis of this machine (axes X Y Z)
                5:12: `4` is not an axis of this machine (axes X Y Z)
                5:24: `1` is given twice in this line
                5:32: the value after `=` is missing
                6:8: `70000.0` is outside ±69999.999
                6:18: `1.2.3` is not a number
                6:24: expected `key=value`, found `X-1.0`
                7:1: `G54` is given again (first in line 5)
            "#]],
        );
    }
}
