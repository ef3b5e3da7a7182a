//! Parameters: substitution into addresses, and parameter arithmetic.

use nc_exec::cnc8x6::formats::{self, Fault, Refusal};
use ncc_catalog::{AddressRole, Dialect};

use crate::{
    Diagnostic,
    cnc8x6::checks::feed,
    cnc8x6::flow::{FlowCheck, Substitution, Visit},
    diagnostic::declare_rules,
    lower::Value,
};

declare_rules! {
    PARAMETER_DIGIT_OVERFLOW = "R301", "parameter-digit-overflow", Error, "A parameter whose value has more digits than the address it is substituted into.";
    SUBSTITUTED_VALUE_OUT_OF_RANGE = "R302", "substituted-value-out-of-range", Error, "A parameter whose value is outside the range of the address it is substituted into.";
    PARAMETER_IN_THOUSANDTHS = "R303", "parameter-in-thousandths", Warning, "A length taken from a parameter written without a decimal point (read in thousandths).";
    FEED_PARAMETER_IN_METRES = "R304", "feed-parameter-in-metres", Error, "A feed per minute from a parameter written with a decimal point, which F reads in m/min, above the machine's feed limit.";
    RESERVED_PARAMETER = "R305", "reserved-parameter", Error, "R95, the control's own parameter, written by the program.";
    NOT_RECOMMENDED_PARAMETER = "R306", "not-recommended-parameter", Warning, "R90 to R94, reserved for future control parameters.";
    PARAMETER_NUMBER_OUT_OF_RANGE = "R307", "parameter-number-out-of-range", Error, "A parameter number above 95.";
    ARITHMETIC_ERROR = "R308", "arithmetic-error", Error, "Parameter arithmetic that fails with the values known before it runs.";
    USED_BEFORE_ASSIGNMENT = "R309", "parameter-used-before-assignment", Warning, "A parameter read before the program assigns it.";
}

/// Substitution checks and arithmetic errors, block by block.
#[derive(Default)]
pub(crate) struct Parameters;

impl FlowCheck for Parameters {
    fn block(&mut self, visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
        let block = visit.block;
        for (word, substitution) in block.words.iter().zip(visit.substitutions) {
            if let Some(Value::Parameter { index: Some(index), index_range, .. }) = &word.value {
                check_number(*index, visit.range(*index_range), out);
                let unassigned =
                    visit.params.from_start && visit.params.origins.get(*index as usize).is_some_and(Option::is_none);
                if unassigned {
                    out.push(Diagnostic::new(
                        &USED_BEFORE_ASSIGNMENT,
                        visit.range(*index_range),
                        format!("R{index} is read before the program assigns it, so it holds whatever an earlier program left; assign it first (R{index}=…)"),
                    ));
                }
            }
            if let Some(substitution) = substitution {
                check_substitution(visit, word, *substitution, out);
            }
        }
        for assignment in &block.assignments {
            if let Some(index) = assignment.index {
                check_number(index, visit.range(assignment.index_range), out);
                if index == 95 {
                    out.push(Diagnostic::new(
                        &RESERVED_PARAMETER,
                        visit.range(assignment.range),
                        "R95 is the control's own parameter and must not be written by a program (its decade 1 is set with `G26 R5=48110095` and cleared with `R5=48210095`)",
                    ));
                }
            }
        }
        // Errors of the control words themselves have rules of their own.
        if let Some((range, error)) = visit.arithmetic_error.filter(|(_, error)| !super::arith::has_own_rule(error)) {
            out.push(Diagnostic::new(&ARITHMETIC_ERROR, *range, format!("parameter arithmetic fails: {error}")));
        }
    }
}

fn check_number(index: u32, range: ncc_syntax::TextRange, out: &mut Vec<Diagnostic>) {
    if let Some(fault) = formats::parameter_number_fault(index) {
        out.push(Diagnostic::new(&PARAMETER_NUMBER_OUT_OF_RANGE, range, fault.message));
    } else if (90..=94).contains(&index) {
        out.push(Diagnostic::new(
            &NOT_RECOMMENDED_PARAMETER,
            range,
            format!("R{index}: R90 to R94 are reserved for future control parameters; use another parameter"),
        ));
    }
}

/// A substituted value against the address's format and range.
pub(crate) fn check_substitution(
    visit: &Visit<'_>,
    word: &crate::lower::Word,
    substitution: Substitution,
    out: &mut Vec<Diagnostic>,
) {
    let catalogue = Dialect::Cnc8x6.catalogue();
    let Some(address) = catalogue.address(std::str::from_utf8(&[word.letter]).unwrap_or("?")) else { return };
    let range = visit.range(word.value_range.unwrap_or(word.range));
    let related = |d: Diagnostic| match substitution.origin {
        Some(origin) if origin.computed => d.with_related(None, origin.range, "the value was computed here"),
        Some(origin) => d.with_related(None, origin.range, "the value was assigned here"),
        None => d,
    };
    let raw = substitution.raw;
    let letter = &address.letter;
    // In a thread block F is the lead, read in µm/rev like a feed per revolution.
    let thread = visit.after.g(0) == Some(Some(33));
    if formats::takes_digits(address) {
        // The address takes the raw digits: `R10=123` → `G123`.
        if let Some(Fault { refusal, message }) =
            formats::substitution_fault(address, raw, thread, &visit.config.machine)
        {
            let rule =
                if refusal == Refusal::Digits { &PARAMETER_DIGIT_OVERFLOW } else { &SUBSTITUTED_VALUE_OUT_OF_RANGE };
            out.push(related(Diagnostic::new(rule, range, message)));
            if refusal != Refusal::Range {
                return;
            }
        }
        // Per minute the point means metres, which the manual recommends
        // (`R10=0.100` is 100 mm/min, 02 §3.5): only a value above the limit
        // is a mistake, mostly mm/min written with a point (`R10=100.`).
        // Per revolution (and for a thread lead) it means mm/rev.
        let limit = i64::from(visit.config.machine.feed_limit);
        if address.role == AddressRole::Feed
            && !thread
            && raw > limit
            && substitution.origin.is_some_and(|o| o.point && !o.computed)
            && let Some(mode) = feed::feed_mode(visit.after, visit.config).filter(|mode| !mode.per_revolution)
        {
            out.push(related(Diagnostic::new(
                &FEED_PARAMETER_IN_METRES,
                range,
                format!(
                    "under G{} the parameter was written with a decimal point, so `{letter}` reads {} m/min ({raw} mm/min), above this machine's maximum feed of {limit} mm/min (`feed-limit` in ncc.toml); for mm/min write the value without the point",
                    mode.code,
                    show(raw)
                ),
            )));
        }
    } else if matches!(address.role, AddressRole::Axis | AddressRole::Interpolation)
        && substitution.origin.is_some_and(|o| !o.point && !o.computed)
        && raw != 0
    {
        out.push(related(Diagnostic::new(
            &PARAMETER_IN_THOUSANDTHS,
            range,
            format!(
                "the parameter was written without a decimal point, so it holds {} mm, not {raw} mm; write `{raw}.` for millimetres",
                show(raw)
            ),
        )));
    }
}

/// A raw value as the real number the parameter holds (`864` → `0.864`).
pub(crate) use nc_exec::cnc8x6::formats::show;
