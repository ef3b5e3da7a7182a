//! Rules decided by one block, the catalogue and the machine configuration.

use ncc_catalog::{Address, AddressRole, Catalogue, Dialect};
use ncc_syntax::{Decimal, TextRange};
use rustc_hash::FxHashMap;

use nc_exec::cnc8x6::formats::{self, Fault, Refusal};

use crate::{
    Config, Diagnostic,
    diagnostic::declare_rules,
    lower::{BlockData, Value, Word},
};

declare_rules! {
    UNKNOWN_CODE = "B201", "unknown-code", Error, "A G code the control does not know.";
    UNKNOWN_ADDRESS = "B202", "unknown-address", Error, "A letter that is no address of the dialect or the configured axes.";
    ADDRESS_REPEATED = "B203", "address-repeated", Error, "An address written twice in one block.";
    GROUP_CONFLICT = "B204", "group-conflict", Error, "Two codes of one G or M group in one block.";
    TOO_MANY_DIGITS = "B205", "too-many-digits", Error, "A value with more digits than its address's format allows.";
    VALUE_OUT_OF_RANGE = "B206", "value-out-of-range", Error, "A value outside its address's range.";
    UNEXPECTED_SIGN = "B207", "unexpected-sign", Error, "A sign on an address that takes only unsigned values.";
    UNEXPECTED_DECIMAL_POINT = "B208", "unexpected-decimal-point", Warning, "A decimal point on a code, count or number.";
    MISSING_REQUIRED_ADDRESS = "B209", "missing-required-address", Error, "A function without the address it needs in its block.";
    NOT_SUBSTITUTABLE = "B210", "not-substitutable", Error, "A parameter used where the control does not substitute one.";
    TOO_MANY_AXES = "B211", "too-many-axes", Error, "More than six coordinates in one block.";
    LENGTH_COMPENSATION_DIGITS = "B212", "length-compensation-digits", Error, "An `&` digit other than 0, 1 or 2.";
    SKIP_DIGIT_IGNORED = "B214", "skip-digit-ignored", Warning, "A digit after `/`, which the control does not evaluate.", unnecessary;
    SKIP_REPEATED = "B215", "skip-repeated", Warning, "More than one `/` in a block.";
    MEANINGLESS_ADDRESS = "B216", "meaningless-address", Warning, "L or Q in a block without a function that reads it.";
    TOO_MANY_PARAMETER_ASSIGNMENTS = "B217", "too-many-parameter-assignments", Error, "More than 95 parameter assignments in one block.";
    DWELL_OVERRIDES_REPEAT = "B219", "dwell-overrides-repeat", Warning, "G04 with a call or jump: Q is the dwell and the call runs once.";
    SWALLOWED_WORDS = "B221", "swallowed-words", Warning, "An unclosed comment that hides words after it.";
    OFFSET_TABLE_FORM = "B223", "offset-table-form", Warning, "G92/G93 without the group-5 code that names the table row.";
    SUBPROGRAM_START_EXTRA_WORDS = "B224", "subprogram-start-extra-words", Error, "A `G79` block with words other than N, G79 and L.";
    BLOCK_SKIP_BEFORE_BLOCK_NUMBER = "B225", "block-skip-before-block-number", Warning, "`/` as the last item of a block, where it skips this block rather than the next.";
    NON_CANONICAL_WORD_ORDER = "B226", "non-canonical-word-order", Info, "Words out of the maximal block format's order (opt-in: off unless named in ncc.toml).", opt_in;
}

/// The order of the maximal block format, the recommended word order:
/// these addresses, the machine's axes 1–6 in their place, then the rest.
const FORMAT_BEFORE_AXES: &[u8] = b"NGD";
const FORMAT_AFTER_AXES: &[u8] = b"IJKR&FSLQHPTM";

/// The codes that read Q (dwell or repetitions) and L (call or jump target).
const READS_Q: [u32; 4] = [4, 71, 72, 73];
const READS_L: [u32; 4] = [71, 72, 73, 79];

pub(crate) fn check(block: &BlockData, config: &Config) -> Vec<Diagnostic> {
    let catalogue = Dialect::Cnc8x6.catalogue();
    let mut out = Vec::new();
    let indirect_g = block.words_with(b'G').any(|w| matches!(w.value, Some(Value::Parameter { .. })));

    let mut seen: [Option<&Word>; 128] = [None; 128];
    let mut axes = Vec::new();
    for word in &block.words {
        let Some(address) = address_of(catalogue, word.letter) else {
            out.push(Diagnostic::new(
                &UNKNOWN_ADDRESS,
                word.address_range,
                format!("`{}` is no address of the CNC8x6 language", char::from(word.letter)),
            ));
            continue;
        };
        if address.role == AddressRole::Axis {
            if !config.machine.is_axis(word.letter) {
                let configured: Vec<String> = config.machine.axes.iter().map(|&a| char::from(a).to_string()).collect();
                out.push(Diagnostic::new(
                    &UNKNOWN_ADDRESS,
                    word.address_range,
                    format!(
                        "the machine has no axis `{}`: its axes are {} (set `machine.axes` in ncc.toml for other letters)",
                        char::from(word.letter),
                        configured.join(", ")
                    ),
                ));
            }
            axes.push(word);
        }
        if address.role != AddressRole::Function {
            let slot = &mut seen[usize::from(word.letter & 0x7F)];
            if let Some(first) = slot {
                out.push(
                    Diagnostic::new(
                        &ADDRESS_REPEATED,
                        word.range,
                        format!(
                            "address `{}` appears twice in this block; each address may be written once (only G and M codes of different groups and R assignments repeat)",
                            char::from(word.letter)
                        ),
                    )
                    .with_related(None, first.range, "first written here"),
                );
            } else {
                *slot = Some(word);
            }
        }
        match &word.value {
            Some(Value::Literal(literal)) => check_literal(word, address, literal, catalogue, config, &mut out),
            Some(Value::Parameter { .. }) if !address.substitutable => out.push(Diagnostic::new(
                &NOT_SUBSTITUTABLE,
                word.value_range.unwrap_or(word.range),
                format!("`{}` cannot take a parameter: write the value itself", address.letter),
            )),
            _ => {}
        }
    }
    if axes.len() > 6 {
        out.push(Diagnostic::new(
            &TOO_MANY_AXES,
            TextRange::new(axes[6].range.start(), axes.last().expect("more than six").range.end()),
            format!("{} coordinates in one block; the control interpolates at most six", axes.len()),
        ));
    }

    check_groups(block, catalogue, &mut out);
    if !indirect_g {
        check_required_addresses(block, catalogue, &mut out);
        check_block_only_addresses(block, &mut out);
    }
    check_assignments(block, catalogue, &mut out);
    check_skip(block, &mut out);
    check_skip_position(block, &mut out);
    check_word_order(block, config, &mut out);
    check_dwell(block, &mut out);
    check_offset_table_form(block, &mut out);
    check_unit_start(block, &mut out);
    check_swallowed_words(block, catalogue, &mut out);
    out
}

fn address_of(catalogue: &Catalogue, letter: u8) -> Option<&Address> {
    catalogue.address(std::str::from_utf8(&[letter]).ok()?)
}

/// Digits, range, sign and decimal point of a literal value.
fn check_literal(
    word: &Word,
    address: &Address,
    value: &Decimal,
    catalogue: &Catalogue,
    config: &Config,
    out: &mut Vec<Diagnostic>,
) {
    let range = word.value_range.unwrap_or(word.range);
    let letter = &address.letter;
    let fault = formats::literal_fault(address, value, &config.machine);
    match fault {
        Some(Fault { refusal: Refusal::Sign, message }) => {
            out.push(Diagnostic::new(&UNEXPECTED_SIGN, range, message));
            return;
        }
        Some(Fault { refusal: Refusal::Digits, message }) => {
            out.push(Diagnostic::new(&TOO_MANY_DIGITS, range, message));
            return;
        }
        _ => {}
    }
    if value.has_point() && address.frac_digits == Some(0) {
        out.push(Diagnostic::new(
            &UNEXPECTED_DECIMAL_POINT,
            range,
            format!("`{letter}` is a code or count without decimals; write it without a decimal point"),
        ));
    }
    if address.role == AddressRole::Function && !value.has_point() && value.sign().is_none() {
        check_code(word, value, catalogue, out);
        return;
    }
    if let Some(Fault { refusal: Refusal::Decade, message }) = &fault {
        out.push(Diagnostic::new(&LENGTH_COMPENSATION_DIGITS, range, message));
        return;
    }
    if let Some(Fault { refusal: Refusal::Range, message }) = fault {
        let d0 = if word.letter == b'D' && value.to_f64() == 0.0 {
            "; `D0` cancels the length corrections only in length-compensation mode B (machine constant 329 decade 7 = 1 in ncc.toml)"
        } else {
            ""
        };
        out.push(Diagnostic::new(&VALUE_OUT_OF_RANGE, range, format!("{message}{d0}")));
    }
}

/// The format's digit limits of a value, shared with the executor.
pub(crate) use nc_exec::cnc8x6::formats::digit_overflow;

fn check_code(word: &Word, value: &Decimal, catalogue: &Catalogue, out: &mut Vec<Diagnostic>) {
    let Some(number) = value.scaled(0).and_then(|v| u32::try_from(v).ok()) else { return };
    let letter = char::from(word.letter);
    if catalogue.code(letter, number).is_none() && catalogue.group_of(letter, number).is_none() {
        let range = word.range;
        out.push(Diagnostic::new(
            &UNKNOWN_CODE,
            range,
            format!("{letter}{number:02} is not a function of the CNC8x6 control (`ncc explain {letter}{number:02}` suggests similar ones)"),
        ));
    }
}

/// One code per G and M group (the open group M14 takes one value too).
fn check_groups(block: &BlockData, catalogue: &Catalogue, out: &mut Vec<Diagnostic>) {
    let mut by_group: FxHashMap<&str, (u32, &Word)> = FxHashMap::default();
    for letter in [b'G', b'M'] {
        for (number, word) in block.codes(letter) {
            let Some(group) = catalogue.group_of(char::from(letter), number) else { continue };
            match by_group.get(group.id.as_str()) {
                Some(&(first, first_word)) if first != number => {
                    let l = char::from(letter);
                    out.push(
                        Diagnostic::new(
                            &GROUP_CONFLICT,
                            word.range,
                            format!(
                                "{l}{number:02} and {l}{first:02} are both in group {} ({}); one code per group may be written in a block",
                                group.id, group.title
                            ),
                        )
                        .with_related(None, first_word.range, format!("{l}{first:02} is here")),
                    );
                }
                Some(_) => {}
                None => {
                    by_group.insert(group.id.as_str(), (number, word));
                }
            }
        }
    }
}

/// Addresses a function needs in its own block (`G71 L`, `G04 Q`). The
/// control words R5–R8 of G26–G29 may also be left from an earlier block,
/// which only the flow can tell (arithmetic's `check_control_words_set`).
fn check_required_addresses(block: &BlockData, catalogue: &Catalogue, out: &mut Vec<Diagnostic>) {
    for letter in [b'G', b'M'] {
        for (number, word) in block.codes(letter) {
            let Some(code) = catalogue.code(char::from(letter), number) else { continue };
            let missing: Vec<&str> = code
                .requires
                .iter()
                .map(String::as_str)
                .filter(|required| !required.starts_with('R') && !block_has(block, required))
                .collect();
            if !missing.is_empty() {
                let what = missing.iter().map(|m| format!("`{m}`")).collect::<Vec<_>>().join(", ");
                out.push(Diagnostic::new(
                    &MISSING_REQUIRED_ADDRESS,
                    word.range,
                    format!("{} ({}) needs {what} in the same block", code.code, code.title),
                ));
            }
        }
    }
}

/// Whether the block writes address `name`.
fn block_has(block: &BlockData, name: &str) -> bool {
    name.bytes().next().is_some_and(|letter| block.word(letter).is_some())
}

/// L and Q are valid only in their block and only mean something there
/// with a call, jump or dwell.
fn check_block_only_addresses(block: &BlockData, out: &mut Vec<Diagnostic>) {
    let reads = |codes: &[u32]| codes.iter().any(|&c| block.has_code(b'G', c));
    if let Some(q) = block.word(b'Q').filter(|_| !reads(&READS_Q)) {
        out.push(Diagnostic::new(
            &MEANINGLESS_ADDRESS,
            q.range,
            "Q has no effect here: it is the dwell of G04 or the repetitions of G71, G72, G73, and holds only in its block",
        ));
    }
    if let Some(l) = block.word(b'L').filter(|_| !reads(&READS_L)) {
        out.push(Diagnostic::new(
            &MEANINGLESS_ADDRESS,
            l.range,
            "L has no effect here: it names the target of G71, G72, G73 or G79, and holds only in its block",
        ));
    }
}

/// Parameter assignments: numbers, values, and the 95-per-block limit.
fn check_assignments(block: &BlockData, catalogue: &Catalogue, out: &mut Vec<Diagnostic>) {
    let Some(r) = catalogue.address("R") else { return };
    for assignment in &block.assignments {
        match &assignment.value {
            Some(Value::Literal(value)) => {
                let range = assignment.value_range.unwrap_or(assignment.range);
                if let Some(Fault { refusal, message }) = formats::assignment_fault(r, value) {
                    let rule = if refusal == Refusal::Digits { &TOO_MANY_DIGITS } else { &VALUE_OUT_OF_RANGE };
                    out.push(Diagnostic::new(rule, range, message));
                }
            }
            Some(Value::Parameter { .. }) => out.push(Diagnostic::new(
                &NOT_SUBSTITUTABLE,
                assignment.value_range.unwrap_or(assignment.range),
                "a parameter cannot be assigned another parameter (`R1=R2`); use parameter arithmetic: `G26 R5=00020001` copies R2 into R1",
            )),
            None => {}
        }
    }
    if block.assignments.len() > 95 {
        out.push(Diagnostic::new(
            &TOO_MANY_PARAMETER_ASSIGNMENTS,
            block.assignments[95].range,
            format!("{} parameter assignments in one block; the control takes at most 95", block.assignments.len()),
        ));
    }
}

/// The raw value a parameter stores: thousandths (`R1=864` → 864,
/// `R1=864.` → 864000).
pub(crate) use nc_exec::cnc8x6::arith::literal_raw as parameter_raw;

fn check_skip(block: &BlockData, out: &mut Vec<Diagnostic>) {
    for digit in &block.skip_digits {
        out.push(Diagnostic::new(
            &SKIP_DIGIT_IGNORED,
            *digit,
            "the digit after `/` is not evaluated: any `/` is skipped when block skip is on",
        ));
    }
    for skip in block.skip.iter().skip(1) {
        out.push(Diagnostic::new(&SKIP_REPEATED, *skip, "this block already has `/`; one is enough"));
    }
}

/// A block ends just before the next N, so a `/` typed in front of a block
/// number belongs to the block before it. (A further `/` after one in its
/// place is only redundant: skip-repeated.)
fn check_skip_position(block: &BlockData, out: &mut Vec<Diagnostic>) {
    let Some(&skip) = block.skip.first() else { return };
    let mut items = block.words.iter().map(|w| w.range).chain(block.assignments.iter().map(|a| a.range));
    if items.all(|item| item.end() <= skip.start()) {
        out.push(Diagnostic::new(
            &BLOCK_SKIP_BEFORE_BLOCK_NUMBER,
            skip,
            "nothing follows this `/` in its block, so it skips this block, not the next one (a block ends just before the next N); to skip the next block, write `/` after its number",
        ));
    }
}

/// The first word written after one that the maximal block format puts
/// later (`N10 F200 X5.`: X belongs before F).
fn check_word_order(block: &BlockData, config: &Config, out: &mut Vec<Diagnostic>) {
    let order: Vec<u8> =
        FORMAT_BEFORE_AXES.iter().chain(&config.machine.axes).chain(FORMAT_AFTER_AXES).copied().collect();
    let mut items: Vec<(TextRange, u8)> = block.words.iter().map(|w| (w.range, w.letter)).collect();
    items.extend(block.assignments.iter().map(|a| (a.range, b'R')));
    items.sort_by_key(|(range, _)| range.start());
    // The word of the latest place in the order seen so far.
    let mut latest: Option<(usize, TextRange, u8)> = None;
    for (range, letter) in items {
        let Some(place) = order.iter().position(|&l| l == letter) else { continue };
        match latest {
            Some((latest_place, latest_range, latest_letter)) if place < latest_place => {
                let order: Vec<String> = order.iter().map(|&l| char::from(l).to_string()).collect();
                let (letter, latest_letter) = (char::from(letter), char::from(latest_letter));
                out.push(
                    Diagnostic::new(
                        &NON_CANONICAL_WORD_ORDER,
                        range,
                        format!(
                            "`{letter}` is written after `{latest_letter}`; the recommended word order, that of the maximal block format, is {}",
                            order.join(" ")
                        ),
                    )
                    .with_related(None, latest_range, format!("`{latest_letter}` is here")),
                );
                return;
            }
            Some((latest_place, ..)) if place == latest_place => {}
            _ => latest = Some((place, range, letter)),
        }
    }
}

fn check_dwell(block: &BlockData, out: &mut Vec<Diagnostic>) {
    let Some((_, dwell)) = block.codes(b'G').find(|(code, _)| *code == 4) else { return };
    if let Some((code, call)) = block.codes(b'G').find(|(code, _)| matches!(code, 71..=73)) {
        out.push(
            Diagnostic::new(
                &DWELL_OVERRIDES_REPEAT,
                call.range,
                format!("with G04 in the block, Q is the dwell time: G{code} runs once, not Q times; put the dwell in a block of its own"),
            )
            .with_related(None, dwell.range, "G04 is here"),
        );
    }
}

fn check_offset_table_form(block: &BlockData, out: &mut Vec<Diagnostic>) {
    for code in [92, 93] {
        let Some((_, word)) = block.codes(b'G').find(|(c, _)| *c == code) else { continue };
        let has_offset_code = block.codes(b'G').any(|(c, _)| (53..=59).contains(&c));
        let writes_tool_table = code == 92 && block.word(b'D').is_some();
        // A tool-table write that lacks its D: `g92-correction-without-d`.
        let writes_corrections = code == 92 && assigns_corrections(block);
        if !has_offset_code && !writes_tool_table && !writes_corrections {
            let message = if code == 92 {
                "G92 names neither the zero-offset row to write (G53 to G59 in the block) nor a tool-offset entry (D)"
            } else {
                "G93 needs the zero-offset row to set (G53 to G59 in the block)"
            };
            out.push(Diagnostic::new(&OFFSET_TABLE_FORM, word.range, message));
        }
    }
}

/// Whether a G92 block assigns correction values (R0 radius, R1–R4 lengths)
/// for the tool-offset table; with axis words it writes a zero-offset row
/// and R0–R4 are plain parameters.
pub(crate) fn assigns_corrections(block: &BlockData) -> bool {
    let catalogue = Dialect::Cnc8x6.catalogue();
    block.assignments.iter().any(|a| matches!(a.index, Some(0..=4)))
        && !block.words.iter().any(|w| catalogue.role_of(w.letter) == Some(AddressRole::Axis))
}

/// A `G79` block holds only N, G79 and L.
fn check_unit_start(block: &BlockData, out: &mut Vec<Diagnostic>) {
    if !block.has_code(b'G', 79) {
        return;
    }
    let extra = block.body_words().find(|w| {
        !(w.letter == b'L' || (w.letter == b'G' && block.codes(b'G').any(|(c, cw)| c == 79 && std::ptr::eq(cw, *w))))
    });
    if let Some(range) = extra.map(|w| w.range).or(block.assignments.first().map(|a| a.range)) {
        out.push(Diagnostic::new(
            &SUBPROGRAM_START_EXTRA_WORDS,
            range,
            "the first block of a subprogram or macrocycle may hold only its number, G79 and L; move the other words to the next block",
        ));
    }
}

/// An unclosed comment ends at the line end, so words typed after its text
/// become part of it (`"TEXT Y200 Z300`).
fn check_swallowed_words(block: &BlockData, catalogue: &Catalogue, out: &mut Vec<Diagnostic>) {
    for comment in block.comments.iter().filter(|c| !c.closed && c.after_words) {
        let tokens: Vec<&str> = comment.body.split_whitespace().collect();
        let trailing_words = tokens.iter().rev().take_while(|t| looks_like_word(t, catalogue)).count();
        // Comments often end by naming a parameter, block or code ("copy
        // R11 into R37", "jump to N50"); only a run of words is program text.
        if trailing_words >= 2 && trailing_words < tokens.len() {
            let words = tokens[tokens.len() - trailing_words..].join(" ");
            out.push(Diagnostic::new(
                &SWALLOWED_WORDS,
                comment.range,
                format!("the comment is not closed, so `{words}` belongs to it and is not executed; close the comment with `\"` before them if they are program words"),
            ));
        }
    }
}

fn looks_like_word(token: &str, catalogue: &Catalogue) -> bool {
    let bytes = token.as_bytes();
    let Some((&letter, rest)) = bytes.split_first() else { return false };
    let rest = rest.strip_prefix(b"-").unwrap_or(rest);
    letter.is_ascii_uppercase()
        && catalogue.role_of(letter).is_some()
        && !rest.is_empty()
        && rest.iter().all(|b| b.is_ascii_digit() || *b == b'.')
        && rest.iter().any(u8::is_ascii_digit)
}
