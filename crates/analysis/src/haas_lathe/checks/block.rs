//! Rules on single blocks, from their words alone (lathe manual §9 rules
//! 1–11, 38, 43–45, 49, 52). The codes' properties come from the
//! catalogue. Rules 12 and 13 are the parser's (`doubled-decimal-point`,
//! `space-in-word`, `template-placeholder`).

use nc_exec::haas_lathe::lower::{HaasBlock, Value, Word};
use ncc_catalog::{AddressRole, Catalogue, Code, Dialect};
use ncc_syntax::{Decimal, TextEdit, TextRange, TextSize};

use crate::{
    Config, Diagnostic,
    db::{BlockChunk, Db, Settings},
    diagnostic::declare_rules,
    haas_lathe::{
        model::{chunk_blocks, code_range},
        walk::drilling_cycle,
    },
};

declare_rules! {
    UNKNOWN_G_CODE = "L001", "unknown-g-code", Error, "A G code the Haas lathe does not have.";
    UNDESCRIBED_CODE = "L002", "undescribed-code", Warning, "A code the manual lists without saying what it does here (G05, G60, G103, G187).";
    SAME_GROUP_CODES = "L003", "same-group-codes", Error, "Two G codes of one modal group in a block.";
    SEVERAL_M_CODES = "L004", "several-m-codes", Error, "More than one M code in a block.";
    UNKNOWN_M_CODE = "L005", "unknown-m-code", Error, "An M code the Haas lathe does not have.";
    OPTIONAL_FUNCTION = "L006", "optional-function", Warning, "A code that is an option of the control (`#` in the manual's tables): the machine must have it.";
    RESTRICTED_CODE = "L007", "restricted-code", Warning, "A code only some machine models have (M41/M42: SL-30/40), or one for service use only (M43, M44, M82).";
    THREAD_ANGLE_WITH_POINT = "L008", "thread-angle-with-point", Error, "The tool angle A of G76 written with a decimal point.";
    DWELL_IN_MILLISECONDS = "L009", "dwell-in-milliseconds", Info, "A dwell P without a decimal point, which counts milliseconds.";
    DWELL_WITHOUT_P = "L010", "dwell-without-p", Error, "G04 without P, the dwell time.";
    AXIS_WITHOUT_POINT = "L011", "axis-without-point", Info, "A coordinate without a decimal point (`X62`), read as whole millimetres (inches under G20).";
    CYCLE_WITHOUT_DEPTH = "L038", "cycle-without-depth", Error, "G71/G72 without a positive depth of cut D, or G73 without a whole positive number of passes D.";
    PECK_WITH_Q_AND_IJK = "L043", "peck-with-q-and-ijk", Error, "G83 with Q (standard pecking) and I, J or K (degressive pecking) in one block.";
    STEP_NOT_POSITIVE = "L044", "step-not-positive", Error, "G83 Q, I, J or K, or G75 I or K, zero or negative.";
    THREAD_HEIGHT_NEGATIVE = "L045", "thread-height-negative", Warning, "G76 with a negative thread height K, which is unsigned.";
    LIVE_TOOL_NEEDED = "L049", "live-tool-needed", Warning, "A code that needs a live (driven) tool, on a machine without a C axis.";
    DRILLING_WITHOUT_R = "L052", "drilling-without-r", Warning, "A drilling cycle without its reference plane R.";
    THREAD_METHOD = "L104", "thread-method", Error, "G76 P other than the cutting methods P1–P4 (lathe manual §9 rule 45, its second part).";
}

/// The findings of the blocks of a chunk; ranges relative to the chunk's
/// start.
#[salsa::tracked(returns(ref))]
pub(crate) fn chunk_findings<'db>(db: &'db dyn Db, chunk: BlockChunk<'db>) -> Vec<Diagnostic> {
    let config = Settings::get(db).config(db);
    let catalogue = Dialect::HaasLathe.catalogue();
    let mut out = Vec::new();
    let mut start = TextSize::from(0);
    for block in chunk_blocks(db, chunk).iter() {
        let checked = Block { block, catalogue };
        let mut found = Vec::new();
        checked.codes(config, &mut found);
        checked.dwell(&mut found);
        checked.axes(&mut found);
        checked.cycles(&mut found);
        out.extend(found.into_iter().map(|d| d.shifted(start)));
        start += block.len;
    }
    out
}

/// A block, with ranges relative to its start.
struct Block<'a> {
    block: &'a HaasBlock,
    catalogue: &'static Catalogue,
}

/// A word's literal value.
fn literal(word: &Word) -> Option<&Decimal> {
    match &word.value {
        Some(Value::Literal(decimal)) => Some(decimal),
        _ => None,
    }
}

impl Block<'_> {
    fn range(&self, word: &Word) -> TextRange {
        word.range
    }

    /// The words `letter` with their literal values.
    fn values(&self, letter: u8) -> impl Iterator<Item = (&Word, &Decimal)> {
        self.block.words_with(letter).filter_map(|word| Some((word, literal(word)?)))
    }

    fn writes(&self, number: u32) -> bool {
        self.block.has_code(b'G', number)
    }

    /// Rules 1–7 and 49: the codes themselves.
    fn codes(&self, config: &Config, out: &mut Vec<Diagnostic>) {
        let mut groups: Vec<(usize, &Word, u32)> = Vec::new();
        for (number, word) in self.block.code_words(b'G') {
            let Some(code) = self.catalogue.code('G', number) else {
                let message = format!("G{number:02} is no G code of the Haas lathe: the control stops with an alarm");
                out.push(Diagnostic::new(&UNKNOWN_G_CODE, self.range(word), message));
                continue;
            };
            if let Some(group) = self.catalogue.modal_group_index('G', number) {
                match groups.iter().find(|&&(g, _, other)| g == group && other != number) {
                    Some(&(_, first, other)) => {
                        let title = self.catalogue.groups[group].title.to_lowercase();
                        let message = format!(
                            "G{other:02} and G{number:02} are both in the {title} group: a block may hold one code of each group"
                        );
                        let diagnostic = Diagnostic::new(&SAME_GROUP_CODES, self.range(word), message).with_related(
                            None,
                            self.range(first),
                            format!("G{other:02}"),
                        );
                        out.push(diagnostic);
                    }
                    None => groups.push((group, word, number)),
                }
            }
            self.properties(code, word, config, out);
        }
        for (index, word) in self.block.words_with(b'M').enumerate() {
            if index > 0 {
                let message = "only one M code may be written in a block: put this one in a block of its own";
                out.push(Diagnostic::new(&SEVERAL_M_CODES, self.range(word), message));
            }
        }
        for (number, word) in self.block.code_words(b'M') {
            match self.catalogue.code('M', number) {
                Some(code) => self.properties(code, word, config, out),
                None => {
                    let message =
                        format!("M{number:02} is no M code of the Haas lathe: the control stops with an alarm");
                    out.push(Diagnostic::new(&UNKNOWN_M_CODE, self.range(word), message));
                }
            }
        }
    }

    /// Rules 2, 6, 7 and 49: what the catalogue says of a code.
    fn properties(&self, code: &Code, word: &Word, config: &Config, out: &mut Vec<Diagnostic>) {
        let name = &code.code;
        let range = self.range(word);
        if !code.described {
            let message = format!(
                "the manual gives {name} no usable description (an empty or doubtful table row, no format): what it does on this control is not known; check the machine's documentation"
            );
            out.push(Diagnostic::new(&UNDESCRIBED_CODE, range, message));
        }
        if code.optional {
            let message = format!("{name} ({}) is an option of the control: the machine must have it", code.title);
            out.push(Diagnostic::new(&OPTIONAL_FUNCTION, range, message));
        }
        if !code.machines.is_empty() {
            let message = format!("{name} exists only on the {}", code.machines.join(" and "));
            out.push(Diagnostic::new(&RESTRICTED_CODE, range, message));
        }
        if code.service {
            let message = format!("{name} is for service use only, not for part programs");
            out.push(Diagnostic::new(&RESTRICTED_CODE, range, message));
        }
        // Haas live tooling comes with the C axis (Haas documentation, not
        // in the manual): a machine described without C has none. G75's
        // deep drilling (001:2572-2581) is written like one groove without
        // Z (001:2497), so it cannot be told apart.
        if code.live_tool && !config.machine.is_axis(b'C') {
            let message = format!(
                "{name} needs a live (driven) tool, and the machine described has no C axis, so no live tooling (add C to `[machine] axes` if it has)"
            );
            out.push(Diagnostic::new(&LIVE_TOOL_NEEDED, range, message));
        }
    }

    /// Rules 9 and 10: the dwell P of G04 and of the drilling cycles.
    fn dwell(&self, out: &mut Vec<Diagnostic>) {
        let dwells = self.block.codes(b'G').any(|number| number == 4 || self.dwell_cycle(number));
        if !dwells {
            return;
        }
        if self.writes(4) && self.block.word(b'P').is_none() {
            let message = "G04 without P: the block gives no dwell time";
            out.push(Diagnostic::new(&DWELL_WITHOUT_P, code_range(self.block, b'G', 4), message));
        }
        // With a point P counts plain seconds: nothing to show.
        for word in self.block.words_with(b'P') {
            let Some(decimal) = literal(word).filter(|d| !d.has_point()) else { continue };
            let milliseconds = decimal.to_f64();
            let message = format!(
                "P{decimal} dwells {} s: without a decimal point P counts milliseconds (P{decimal}. would be {} s)",
                milliseconds / 1000.0,
                milliseconds
            );
            out.push(Diagnostic::new(&DWELL_IN_MILLISECONDS, self.range(word), message));
        }
    }

    /// Whether the cycle `number` reads P as a dwell, by the unit the
    /// catalogue gives its P.
    fn dwell_cycle(&self, number: u32) -> bool {
        let unit = |cycle: &ncc_catalog::Cycle| {
            cycle.addresses.iter().any(|a| a.letter == "P" && a.unit.as_deref() == Some("ms or s"))
        };
        self.catalogue.cycles_for(&format!("G{number:02}")).any(unit)
    }

    /// Rule 11: coordinates without a decimal point.
    fn axes(&self, out: &mut Vec<Diagnostic>) {
        // G65's words are the macro's arguments.
        if self.writes(65) {
            return;
        }
        for word in &self.block.words {
            if self.catalogue.role_of(word.letter) != Some(AddressRole::Axis) {
                continue;
            }
            let Some(decimal) = literal(word).filter(|d| !d.has_point() && d.to_f64() != 0.0) else { continue };
            let letter = char::from(word.letter);
            let message = format!(
                "{letter}{decimal} has no decimal point: the Haas control reads it as {} whole units (mm, inches under G20), a control that reads thousandths as {}; write {letter}{decimal}. to be sure",
                decimal.to_f64(),
                decimal.to_f64() / 1000.0
            );
            out.push(Diagnostic::new(&AXIS_WITHOUT_POINT, self.range(word), message));
        }
    }

    /// Rules 8, 38, 43–45, 52: the words of cycles.
    fn cycles(&self, out: &mut Vec<Diagnostic>) {
        for number in self.block.codes(b'G') {
            self.depth(number, out);
            if drilling_cycle(self.catalogue, number) && self.block.word(b'R').is_none() {
                let message = format!(
                    "G{number:02} without R: the cycle has no reference plane to start drilling from and to return to"
                );
                out.push(Diagnostic::new(&DRILLING_WITHOUT_R, code_range(self.block, b'G', number), message));
            }
        }
        if self.writes(83) {
            let degressive: Vec<&Word> =
                [b'I', b'J', b'K'].iter().filter_map(|&letter| self.block.word(letter)).collect();
            if let (Some(q), Some(first)) = (self.block.word(b'Q'), degressive.first()) {
                let message = format!(
                    "G83 with Q and {}: Q is the peck of standard pecking, I, J and K those of degressive pecking; the manual forbids both in one block",
                    char::from(first.letter)
                );
                let diagnostic = Diagnostic::new(&PECK_WITH_Q_AND_IJK, self.range(q), message).with_related(
                    None,
                    self.range(first),
                    char::from(first.letter).to_string(),
                );
                out.push(diagnostic);
            }
            self.positive(83, b"QIJK", out);
        }
        if self.writes(75) {
            self.positive(75, b"IK", out);
        }
        if self.writes(76) {
            self.thread(out);
        }
    }

    /// Rule 44: the steps of G83 and G75 are positive.
    fn positive(&self, number: u32, letters: &[u8], out: &mut Vec<Diagnostic>) {
        for &letter in letters {
            for (word, value) in self.values(letter).filter(|&(_, value)| value.to_f64() <= 0.0) {
                let letter = char::from(letter);
                let message = format!("{letter}{value}: G{number} takes {letter} as a positive depth or step only");
                out.push(Diagnostic::new(&STEP_NOT_POSITIVE, self.range(word), message));
            }
        }
    }

    /// Rules 8 and 45 (with L104): the words of G76.
    fn thread(&self, out: &mut Vec<Diagnostic>) {
        for word in self.block.words_with(b'A') {
            let Some(decimal) = literal(word).filter(|d| d.has_point()) else { continue };
            let mut diagnostic = Diagnostic::new(
                &THREAD_ANGLE_WITH_POINT,
                self.range(word),
                format!("G76 takes the tool angle A without a decimal point: A{decimal}"),
            );
            // A whole angle keeps its value without the point.
            if let (Some(whole), Some(value)) = (decimal.scaled(0), word.value_range) {
                let edit = TextEdit::replace(value, whole.to_string());
                diagnostic = diagnostic.with_fix(format!("Write A{whole}"), vec![edit]);
            }
            out.push(diagnostic);
        }
        for (word, value) in self.values(b'K').filter(|&(_, value)| value.to_f64() < 0.0) {
            let message = format!("the thread height K is written without a sign: K{value} is negative");
            out.push(Diagnostic::new(&THREAD_HEIGHT_NEGATIVE, self.range(word), message));
        }
        for (word, value) in self.values(b'P').filter(|&(_, value)| ![1.0, 2.0, 3.0, 4.0].contains(&value.to_f64())) {
            let message = format!("G76 P{value} is no cutting method: P1 to P4 choose how the passes infeed");
            out.push(Diagnostic::new(&THREAD_METHOD, self.range(word), message));
        }
    }

    /// Rule 38: the D of the cycles that require it, a depth (a positive
    /// length) or, where the catalogue gives D no unit, a number of passes.
    fn depth(&self, number: u32, out: &mut Vec<Diagnostic>) {
        let Some(code) = self.catalogue.code('G', number).filter(|code| code.requires.iter().any(|r| r == "D")) else {
            return;
        };
        let Some(meaning) = self.catalogue.cycles_for(&code.code).find_map(|cycle| {
            cycle.addresses.iter().find(|address| address.letter == "D").map(|d| (d.meaning.as_str(), d.unit.is_some()))
        }) else {
            return;
        };
        let (meaning, depth) = meaning;
        // The meaning's first clause, as part of a sentence.
        let meaning = meaning.split(['(', '.']).next().unwrap_or_default().trim_end();
        let meaning = meaning.get(..1).map_or(String::new(), str::to_lowercase) + meaning.get(1..).unwrap_or_default();
        let name = &code.code;
        let Some(word) = self.block.word(b'D') else {
            let message = format!("{name} without D, {meaning}: the control cannot rough without it");
            out.push(Diagnostic::new(&CYCLE_WITHOUT_DEPTH, code_range(self.block, b'G', number), message));
            return;
        };
        let Some(decimal) = literal(word) else { return };
        let value = decimal.to_f64();
        let wrong = if depth { value <= 0.0 } else { value < 1.0 || value.fract() != 0.0 };
        if wrong {
            let must = if depth { "a positive depth" } else { "a whole number of passes, 1 or more" };
            let message = format!("{name} D{decimal} is no valid D, {meaning}: it must be {must}");
            out.push(Diagnostic::new(&CYCLE_WITHOUT_DEPTH, self.range(word), message));
        }
    }
}
