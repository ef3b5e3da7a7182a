//! Which block runs after a block: calls, jumps and returns as the control
//! decides them. The executor and the checker's flow walk both follow a
//! program with these, so that they take the same way through it.

use std::collections::BTreeMap;

use ncc_syntax::Decimal;

use crate::{
    cnc8x6::arith::{self, Parameters},
    cnc8x6::lower::{BlockData, Value, Word},
};

/// How a block passes control on once its work is done.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BlockFlow {
    Next,
    /// M02/M30: the program ends.
    End,
    /// `G70`: back from a subprogram.
    Return,
    /// `G71 L` (or `G72 L`, a macrocycle file): run subprogram `label`
    /// `times` times.
    Call {
        label: u32,
        times: u32,
        macrocycle: bool,
    },
    /// `G73 L Q`: jump to block N`label`, `times` times in all.
    Jump {
        label: u32,
        times: u32,
    },
}

/// What follows a block once its work is done: M02/M30 end the program;
/// otherwise its call or jump runs, at the end of the block (with G04, Q is
/// the dwell and a call runs once, 01 §4.8). `has` tells the block's codes
/// (literal or from a parameter: `GR20` holding 73 jumps, 78 does nothing);
/// `integer` reads L and Q as the block leaves the parameters.
pub fn block_flow(
    block: &BlockData,
    has: impl Fn(u8, u32) -> bool,
    integer: impl Fn(&Word) -> Option<u32>,
) -> BlockFlow {
    if has(b'M', 2) || has(b'M', 30) {
        return BlockFlow::End;
    }
    let label = block.word(b'L').and_then(&integer);
    let count = block.word(b'Q').filter(|_| !has(b'G', 4)).and_then(&integer);
    match label {
        Some(label) if has(b'G', 71) || has(b'G', 72) => {
            BlockFlow::Call { label, times: count.unwrap_or(1).max(1), macrocycle: has(b'G', 72) }
        }
        // Q(n) runs the section n+1 times (01 §4.7): n jumps back.
        Some(label) if has(b'G', 73) => BlockFlow::Jump { label, times: count.unwrap_or(1) },
        _ if has(b'G', 70) => BlockFlow::Return,
        _ => BlockFlow::Next,
    }
}

/// A dimensionless word's whole number (codes, L, Q, T): the literal
/// written without a point, or a parameter's raw digits (`R21=40` → G40).
pub fn integer(word: &Word, params: &Parameters) -> Option<u32> {
    match word.value.as_ref()? {
        Value::Literal(decimal) => whole_number(decimal),
        value => u32::try_from(arith::reference(value, params)?).ok(),
    }
}

/// A dimensionless literal (a code, L, Q, T): written without a point.
pub(crate) fn whole_number(decimal: &Decimal) -> Option<u32> {
    if decimal.has_point() { None } else { u32::try_from(decimal.scaled(0)?).ok() }
}

/// The jumps taken so far from each jump block (by block index), until its
/// count runs out.
#[derive(Debug, Clone, Default, PartialEq, Eq, Hash)]
pub struct JumpCounts(BTreeMap<usize, u32>);

impl JumpCounts {
    /// Whether the jump of block `at`, which jumps `times` times in all,
    /// jumps now. When its count has run out it does not, and the count
    /// starts again for the next time the section is reached.
    pub fn jumps(&mut self, at: usize, times: u32) -> bool {
        let taken = self.0.entry(at).or_default();
        if *taken < times {
            *taken += 1;
            true
        } else {
            self.0.remove(&at);
            false
        }
    }

    /// Block `at` passed on without jumping (`GRxx` read as G78): its count
    /// starts again.
    pub fn passed(&mut self, at: usize) {
        if !self.0.is_empty() {
            self.0.remove(&at);
        }
    }

    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// Moves the counts with their blocks (`moved` gives a block's new
    /// index); `false`, and the counts unchanged, if a block has none.
    pub fn move_blocks(&mut self, moved: impl Fn(usize) -> Option<usize>) -> bool {
        let counts: Option<BTreeMap<usize, u32>> =
            self.0.iter().map(|(&at, &taken)| Some((moved(at)?, taken))).collect();
        counts.map(|counts| self.0 = counts).is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::JumpCounts;

    /// `G73 L Q2` jumps twice and then passes, and jumps again the next
    /// time the section is reached; a pass without jumping starts the
    /// count again.
    #[test]
    fn a_jump_counts_its_repetitions_and_starts_again() {
        let mut counts = JumpCounts::default();
        let taken: Vec<bool> = (0..4).map(|_| counts.jumps(7, 2)).collect();
        assert_eq!(taken, [true, true, false, true]);
        counts.passed(7);
        assert!(counts.is_empty());
        assert!(counts.jumps(7, 1));
        assert!(counts.move_blocks(|at| Some(at + 3)));
        assert!(!counts.jumps(10, 1));
        assert!(counts.jumps(10, 1));
        assert!(!counts.move_blocks(|_| None));
        assert!(!counts.jumps(10, 1), "a failed move keeps the counts");
    }
}
