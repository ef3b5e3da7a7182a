//! The Sinumerik dialect's part of the benchmarks: a generated parametric
//! program, the other shape of Sinumerik code beside CAM output (which
//! [`crate::cnc8x6::progen`] writes in every dialect).

use std::fmt::Write;

/// The lines of one pocket of [`parametric`].
const POCKET_LINES: usize = 20;

/// A deterministic parametric program of about `lines` lines (at least one
/// pocket): definitions, then pockets, each computed from R parameters and
/// variables with expressions, function calls, a `WHILE` loop with a
/// forward jump, a `FOR` loop and an `IF`/`ELSE`, indented as people write
/// them. It has no syntax error.
pub fn parametric(lines: usize) -> String {
    let mut out = String::with_capacity(lines * 28);
    out.push_str("%_N_PARAMETRIC_MPF\n");
    out.push_str("; pockets computed from parameters\n");
    out.push_str("DEF REAL DEPTH=-2.5, STEP=0.4, ANGLE\n");
    out.push_str("DEF INT ROW, PASSES=3\n");
    out.push_str("N10 G54 G90 G17 G0 X0 Y0 Z5 M3 S8000\n");
    let header_lines = 5;
    let pockets = lines.saturating_sub(header_lines + 1).div_ceil(POCKET_LINES).max(1);
    for k in 0..pockets {
        let offset = (k % 97) as f64 * 0.25;
        let _ = write!(
            out,
            "; POCKET {k}\n\
             R1={offset:.2}+{k} MOD 50*STEP R2=R1/2+SIN(R1*3.6)*0.8\n\
             R10=0\n\
             WHILE R10<PASSES\n\
             \x20 R11=R10*STEP+R1\n\
             \x20 IF R11>{limit} GOTOF SKIP{k}\n\
             \x20 G1 X=R11 Y=R2+R10*0.5 Z=DEPTH-R10*0.1 F1200\n\
             \x20 SKIP{k}:\n\
             \x20 R10=R10+1\n\
             ENDWHILE\n\
             FOR ROW=1 TO 3\n\
             \x20 ANGLE=ROW*30+{k} MOD 7\n\
             \x20 G1 X=R1+COS(ANGLE)*5 Y=R2+SIN(ANGLE)*5\n\
             ENDFOR\n\
             IF (R1>5) AND (R2<=100)\n\
             \x20 G0 Z=5\n\
             ELSE\n\
             \x20 G1 Z=DEPTH/2 F=R10*100+400\n\
             ENDIF\n\
             MSG(\"POCKET \"<<{k})\n",
            limit = 10 + k % 13,
        );
    }
    out.push_str("M30\n");
    out
}

#[cfg(test)]
mod tests {
    use ncc_syntax::{Dialect, Parse};

    use super::*;

    #[test]
    fn parametric_programs_parse_without_errors() {
        let text = parametric(1000);
        let parse = Parse::new(&text, Dialect::Sinumerik);
        assert!(parse.errors().is_empty(), "{:?}", &parse.errors()[..1]);
        let lines = text.lines().count();
        assert!((1000..1000 + POCKET_LINES).contains(&lines), "{lines} lines");
        assert_eq!(text.lines().filter(|line| line.starts_with("; POCKET")).count(), 50);
        for keyword in ["DEF REAL", "WHILE", "FOR ", "IF ", "ELSE", "GOTOF", "SIN("] {
            assert!(text.contains(keyword), "{keyword}");
        }
    }

    #[test]
    fn each_pocket_is_its_number_of_lines() {
        let pocket = parametric(POCKET_LINES + 6);
        assert_eq!(pocket.lines().count(), 5 + POCKET_LINES + 1);
    }
}
