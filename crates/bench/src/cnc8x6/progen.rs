//! A deterministic generator of surfacing programs, as a CAM system writes them.
//!
//! The tool zig-zags over a wavy surface in rows along X: many short linear
//! moves in X, Y and Z, a semicircular turnaround arc at the end of each row
//! (about every 50 blocks), a comment every 200 blocks, and a lift and
//! return to the start when the part's Y extent is used up. The toolpath is
//! produced once as [`Move`]s and written in either dialect, so both files
//! describe exactly the same motion.

use std::fmt::Write;

use crate::lcg::Lcg;

/// The syntax to write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Syntax {
    /// MEFI CNC8x6: `%` header, `N` on every block, `"comments"`, `*` end.
    Cnc8x6,
    /// RS274/NGC as LinuxCNC and the `gcode` crate read it: `(comments)`, `M2`.
    Ngc,
    /// Haas lathe: `O1 (TITLE)`, `(comments)`, `M30`, no block numbers; the
    /// toolpath in the lathe's ZX plane, Y written as Z and the surface's
    /// height left out, so that arcs in XY become arcs by I/K in ZX.
    HaasLathe,
    /// Siemens Sinumerik: a `%_N_…_MPF` header, `N` on every block,
    /// `;comments`, `M30`.
    Sinumerik,
}

/// One step of the toolpath.
#[derive(Debug, Clone, PartialEq)]
pub enum Move {
    /// Set-up: offset, absolute, plane, spindle; then rapid to the point.
    Start {
        x: f64,
        y: f64,
        z: f64,
        spindle_rpm: u32,
    },
    Rapid {
        x: Option<f64>,
        y: Option<f64>,
        z: Option<f64>,
    },
    Linear {
        x: f64,
        y: f64,
        z: f64,
        feed: Option<u32>,
    },
    /// Arc in the XY plane to (`x`, `y`), centre at `i`, `j` from the start.
    Arc {
        clockwise: bool,
        x: f64,
        y: f64,
        i: f64,
        j: f64,
    },
    Comment(String),
    End,
}

/// Rows are this many linear moves long, so an arc comes every ~50 blocks.
const MOVES_PER_ROW: usize = 49;
const STEP: f64 = 0.4;
const TURN_RADIUS: f64 = 1.5;
const Y_EXTENT: f64 = 600.0;
const FEED: u32 = 2400;

/// The toolpath of a program of exactly `blocks` blocks (at least 4).
pub fn surfacing(blocks: usize) -> Vec<Move> {
    let blocks = blocks.max(4);
    let mut path = Toolpath { moves: Vec::with_capacity(blocks + blocks / 200 + 1), blocks: 0 };
    path.push(Move::Start { x: 0.0, y: 0.0, z: 5.0, spindle_rpm: 8000 });
    path.push(Move::Linear { x: 0.0, y: 0.0, z: surface(0.0, 0.0), feed: Some(FEED) });
    let (mut x, mut y, mut row, mut along) = (0.0f64, 0.0f64, 0usize, 0usize);
    while path.blocks < blocks - 2 {
        if path.blocks.is_multiple_of(200) {
            path.moves.push(Move::Comment(format!("ROW {row} BLOCK {}", path.blocks)));
        }
        if along == MOVES_PER_ROW {
            along = 0;
            row += 1;
            if y + 2.0 * TURN_RADIUS > Y_EXTENT {
                // Start the next layer of passes from the origin.
                path.push(Move::Rapid { x: None, y: None, z: Some(5.0) });
                path.push(Move::Rapid { x: Some(0.0), y: Some(0.0), z: None });
                (x, y, row) = (0.0, 0.0, 0);
                path.push(Move::Linear { x, y, z: surface(x, y), feed: None });
                continue;
            }
            // Rows alternate direction: turn counter-clockwise at the right
            // end, clockwise at the left end.
            let clockwise = row % 2 == 0;
            path.push(Move::Arc { clockwise, x, y: y + 2.0 * TURN_RADIUS, i: 0.0, j: TURN_RADIUS });
            y += 2.0 * TURN_RADIUS;
            continue;
        }
        along += 1;
        x += if row % 2 == 0 { STEP } else { -STEP };
        path.push(Move::Linear { x, y, z: surface(x, y), feed: None });
    }
    path.push(Move::Rapid { x: None, y: None, z: Some(5.0) });
    path.push(Move::End);
    path.moves
}

struct Toolpath {
    moves: Vec<Move>,
    blocks: usize,
}

impl Toolpath {
    fn push(&mut self, m: Move) {
        self.blocks += 1;
        self.moves.push(m);
    }
}

/// The machined surface: gentle waves a CAM system would follow closely.
fn surface(x: f64, y: f64) -> f64 {
    -2.0 + 0.8 * (x / 7.0).sin() * (y / 11.0).cos() + 0.15 * ((x + y) / 3.0).sin()
}

/// Writes the toolpath as program text.
pub fn write(moves: &[Move], syntax: Syntax) -> String {
    let mut out = String::with_capacity(moves.len() * 34);
    let mut n = 0u32;
    match syntax {
        Syntax::Cnc8x6 => out.push_str("%1 \"SURFACING\"\n"),
        Syntax::HaasLathe => out.push_str("O1 (SURFACING)\n"),
        Syntax::Sinumerik => out.push_str("%_N_SURFACING_MPF\n"),
        Syntax::Ngc => {}
    }
    let lathe = syntax == Syntax::HaasLathe;
    for m in moves {
        let block_start = out.len();
        let numbered = matches!(syntax, Syntax::Cnc8x6 | Syntax::Sinumerik);
        if numbered && !matches!(m, Move::Comment(_)) {
            n += 1;
            let _ = write!(out, "N{n} ");
        }
        match *m {
            Move::Start { x, y, z, spindle_rpm } => {
                let code = if syntax == Syntax::Cnc8x6 { "G00" } else { "G0" };
                // CAM output for this control joins its short segments
                // with continuity G23.
                let continuity = if syntax == Syntax::Cnc8x6 { " G23" } else { "" };
                if lathe {
                    let _ = write!(out, "G54 G18 G97 G98 G0 X{x:.3} Z{y:.3} M03 S{spindle_rpm}");
                } else {
                    let _ = write!(out, "G54 G90 G17 {code}{continuity} X{x:.3} Y{y:.3} Z{z:.3} M03 S{spindle_rpm}");
                }
            }
            Move::Rapid { x, y, z } => {
                out.push_str("G0");
                let axes = if lathe { [('X', x), ('Z', y), ('Y', None)] } else { [('X', x), ('Y', y), ('Z', z)] };
                for (letter, value) in axes {
                    if let Some(value) = value {
                        let _ = write!(out, " {letter}{value:.3}");
                    }
                }
            }
            Move::Linear { x, y, z, feed } => {
                if lathe {
                    let _ = write!(out, "G1 X{x:.3} Z{y:.3}");
                } else {
                    let _ = write!(out, "G1 X{x:.3} Y{y:.3} Z{z:.3}");
                }
                if let Some(feed) = feed {
                    let _ = write!(out, " F{feed}");
                }
            }
            Move::Arc { clockwise, x, y, i, j } => {
                let code = if clockwise { "G2" } else { "G3" };
                if lathe {
                    let _ = write!(out, "{code} X{x:.3} Z{y:.3} I{i:.3} K{j:.3}");
                } else {
                    let _ = write!(out, "{code} X{x:.3} Y{y:.3} I{i:.3} J{j:.3}");
                }
            }
            Move::Comment(ref text) => match syntax {
                Syntax::Cnc8x6 => {
                    let _ = write!(out, "\"{text}\"");
                }
                Syntax::Ngc | Syntax::HaasLathe => {
                    let _ = write!(out, "({text})");
                }
                Syntax::Sinumerik => {
                    let _ = write!(out, "; {text}");
                }
            },
            Move::End => out.push_str(if syntax == Syntax::Ngc { "M2" } else { "M30" }),
        }
        debug_assert!(out.len() - block_start <= 80, "generated line too long");
        out.push('\n');
    }
    if syntax == Syntax::Cnc8x6 {
        out.push_str("*\n");
    }
    out
}

/// The dialect whose CAM output other dialects' parse throughput is
/// compared with.
pub const REFERENCE: ncc_syntax::Dialect = ncc_syntax::Dialect::Cnc8x6;

/// The motion codes of generated programs, in every syntax's spelling.
const MOTIONS: [&str; 8] = ["G0", "G00", "G1", "G01", "G2", "G02", "G3", "G03"];

/// Whether `line` of a generated program is a motion block: one of its
/// words is a motion code. Block numbers do not tell (Haas programs have
/// none).
pub fn is_motion_block(line: &str) -> bool {
    line.split(' ').any(|word| MOTIONS.contains(&word))
}

/// Whether `line` of a generated program is a straight move at feed.
pub fn is_linear_move(line: &str) -> bool {
    line.split(' ').any(|word| word == "G1")
}

/// Counts the blocks of a generated program (comment lines excluded).
pub fn block_count(moves: &[Move]) -> usize {
    moves.iter().filter(|m| !matches!(m, Move::Comment(_))).count()
}

/// Hostile input: `len` random letters and digits on one line, seeded. The
/// parser and the checks find something every few characters.
pub fn random_line(len: usize, seed: u64) -> String {
    const ALPHABET: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789";
    let mut rng = Lcg::new(seed);
    (0..len).map(|_| char::from(ALPHABET[rng.below(ALPHABET.len())])).collect()
}

/// The offset of a random character of the first G word at or after a
/// random line within ten lines of `offset` (generated comments hold none).
pub fn g_code_near(text: &str, offset: usize, rng: &mut Lcg) -> Option<usize> {
    let mut start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    let (up, down) = match rng.below(21) {
        lines @ 0..10 => (lines + 1, 0),
        lines => (0, lines - 10),
    };
    for _ in 0..up {
        start = text[..start.saturating_sub(1)].rfind('\n').map_or(0, |i| i + 1);
    }
    for _ in 0..down {
        start = text[start..].find('\n').map_or(start, |i| start + i + 1);
    }
    let mut line_start = start;
    for line in text[start..].split_inclusive('\n') {
        let mut word_start = line_start;
        for word in line.trim_end().split(' ') {
            if word.len() > 1 && word.starts_with('G') && word.as_bytes()[1].is_ascii_digit() {
                return Some(word_start + rng.below(word.len()));
            }
            word_start += word.len() + 1;
        }
        line_start += line.len();
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_block_count_and_shape() {
        for blocks in [4, 50, 1000, 12345] {
            let moves = surfacing(blocks);
            assert_eq!(block_count(&moves), blocks);
        }
        let moves = surfacing(1000);
        let arcs = moves.iter().filter(|m| matches!(m, Move::Arc { .. })).count();
        let comments = moves.iter().filter(|m| matches!(m, Move::Comment(_))).count();
        assert!((15..=25).contains(&arcs), "{arcs} arcs");
        assert_eq!(comments, 4);
    }

    #[test]
    fn arcs_end_on_their_circle() {
        let moves = surfacing(5000);
        let mut at = (0.0, 0.0);
        for m in &moves {
            match *m {
                Move::Linear { x, y, .. } => at = (x, y),
                Move::Rapid { x, y, .. } => at = (x.unwrap_or(at.0), y.unwrap_or(at.1)),
                Move::Arc { x, y, i, j, .. } => {
                    let centre = (at.0 + i, at.1 + j);
                    let r0 = (i * i + j * j).sqrt();
                    let r1 = ((x - centre.0).powi(2) + (y - centre.1).powi(2)).sqrt();
                    assert!((r0 - r1).abs() < 1e-9);
                    at = (x, y);
                }
                _ => {}
            }
        }
    }

    #[test]
    fn both_syntaxes_have_one_line_per_block() {
        let moves = surfacing(500);
        let cnc = write(&moves, Syntax::Cnc8x6);
        let ngc = write(&moves, Syntax::Ngc);
        assert!(cnc.starts_with("%1 \"SURFACING\"\nN1 G54 G90 G17 G00 G23 X0.000 Y0.000 Z5.000 M03 S8000\n"));
        assert!(cnc.ends_with("N500 M30\n*\n"));
        assert!(ngc.ends_with("M2\n"));
        assert_eq!(cnc.lines().count(), ngc.lines().count() + 2);
    }
}
