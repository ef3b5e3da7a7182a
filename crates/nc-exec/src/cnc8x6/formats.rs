//! The catalogue's address formats applied to values: what the control
//! refuses in a value written in a block or substituted from a parameter,
//! worded once for the checker, which finds it before the program runs,
//! and the executor, which stops there as the control does.

use ncc_catalog::{Address, AddressRole};
use ncc_syntax::Decimal;

use crate::{
    cnc8x6::arith::{MAX_RAW, Raw, literal_raw},
    machine::MachineConfig,
};

/// Why the control refuses a value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Refusal {
    /// A sign on an address that takes only unsigned values.
    Sign,
    /// More digits than the address's format has.
    Digits,
    /// Outside the address's range.
    Range,
    /// An `&` digit other than 0 (off), 1 (add) or 2 (subtract): each
    /// switches one axis's length correction (02 §1.18).
    Decade,
}

/// A value the control refuses, and what to tell the programmer.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Fault {
    pub refusal: Refusal,
    pub message: String,
}

impl Fault {
    fn new(refusal: Refusal, message: String) -> Fault {
        Fault { refusal, message }
    }
}

/// A literal written at `address` on `machine`: a sign it does not take,
/// more digits than its format has, or a value outside its range.
pub fn literal_fault(address: &Address, value: &Decimal, machine: &MachineConfig) -> Option<Fault> {
    let letter = &address.letter;
    if value.sign().is_some() && !address.signed {
        return Some(Fault::new(Refusal::Sign, format!("`{letter}` takes only unsigned values; remove the sign")));
    }
    if let Some(message) = digit_overflow(address, value) {
        return Some(Fault::new(Refusal::Digits, message));
    }
    if switches_lengths_outside_decades(address, &value.to_string()) {
        return Some(Fault::new(
            Refusal::Decade,
            format!(
                "`{letter}{value}`: each digit assigns one axis's length correction and must be 0 (off), 1 (add) or 2 (subtract)"
            ),
        ));
    }
    let digits = value.significant_int_digits();
    let outside =
        !surely_within(address.bounds, digits, value.is_negative()) && outside_range(address, value.to_f64(), machine);
    outside.then(|| {
        Fault::new(Refusal::Range, format!("`{letter}{value}` is outside the range of `{letter}`: {}", range(address)))
    })
}

/// A literal assigned to a parameter (`R5=…`, `parameter` the address of
/// R): more digits than its format has, or a value outside ±69999.999.
pub fn assignment_fault(parameter: &Address, value: &Decimal) -> Option<Fault> {
    if let Some(message) = digit_overflow(parameter, value) {
        return Some(Fault::new(Refusal::Digits, message));
    }
    literal_raw(value)
        .is_none_or(|raw| raw.abs() > MAX_RAW)
        .then(|| Fault::new(Refusal::Range, format!("`{value}` is outside the parameter range {}", range(parameter))))
}

/// A parameter number the control does not have.
pub fn parameter_number_fault(index: u32) -> Option<Fault> {
    (index as usize >= crate::cnc8x6::arith::PARAMETER_COUNT).then(|| {
        Fault::new(
            Refusal::Range,
            format!("R{index}: the control has parameters R0 to R{}", crate::cnc8x6::arith::PARAMETER_COUNT - 1),
        )
    })
}

/// An address's range as messages write it: `min to max`.
fn range(address: &Address) -> String {
    format!("{} to {}", address.min.as_deref().unwrap_or_default(), address.max.as_deref().unwrap_or_default())
}

/// The format's digit limits: significant digits before the point (leading
/// zeros may always be written) and digits after it (trailing zeros may be).
pub fn digit_overflow(address: &Address, value: &Decimal) -> Option<String> {
    let int_limit = int_limit(address, value.has_point())?;
    let int = value.significant_int_digits();
    let letter = &address.letter;
    if int > u32::from(int_limit) {
        let form = if address.int_digits_without_point.is_some() {
            if value.has_point() { " with a decimal point" } else { " without a decimal point" }
        } else {
            ""
        };
        return Some(format!(
            "`{letter}{value}` has {int} digits before the point; the format of `{letter}` allows {int_limit}{form}"
        ));
    }
    let frac_limit = u32::from(address.frac_digits.unwrap_or(0));
    // Trailing zeros are counted only when there are more decimals than
    // the limit: every word of a program comes here.
    let frac = || value.significant_frac_digits();
    if value.has_point() && frac_limit > 0 && value.frac_digits() > frac_limit && frac() > frac_limit {
        let frac = frac();
        return Some(format!(
            "`{letter}{value}` has {frac} decimals; `{letter}` takes at most {frac_limit} (the control's resolution)"
        ));
    }
    None
}

/// The significant digits before the point the format of `address` allows
/// in a value written with or without a point; `None`: its digits are not
/// limited.
fn int_limit(address: &Address, point: bool) -> Option<u8> {
    if point { address.int_digits } else { address.int_digits_without_point.or(address.int_digits) }
}

/// The literals an address plainly takes, worked out once from its format:
/// the run checks every word it runs, and nearly all are plainly right.
/// What [`PlainLiterals::take`] does not take, [`literal_fault`] looks at.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PlainLiterals {
    signed: bool,
    /// The digits before the point allowed without and with a point
    /// (`u8::MAX`: not limited).
    int_digits: [u8; 2],
    /// The decimals allowed (0: not limited).
    frac_digits: u8,
    /// For values not negative and negative: bit `d` is set when any `d`
    /// significant digits before the point keep a value within the range
    /// (all bits without a range).
    within: [u16; 2],
}

impl PlainLiterals {
    /// What `address` plainly takes; none of it when there is no address.
    pub fn of(address: Option<&Address>) -> PlainLiterals {
        // `&` is read digit by digit, not by its range.
        let Some(address) = address.filter(|address| address.role != AddressRole::LengthCompensation) else {
            return PlainLiterals::default();
        };
        // Without a range no value is outside it.
        let within = |negative| match address.bounds {
            None => u16::MAX,
            bounds => (0..POWERS.len() as u32)
                .filter(|&digits| surely_within(bounds, digits, negative))
                .fold(0, |mask, digits| mask | 1 << digits),
        };
        PlainLiterals {
            signed: address.signed,
            int_digits: [false, true].map(|point| int_limit(address, point).unwrap_or(u8::MAX)),
            // Without a limit before the point, digit_overflow counts no decimals.
            frac_digits: address.int_digits.and(address.frac_digits).unwrap_or(0),
            within: [within(false), within(true)],
        }
    }

    /// Whether `value` is plainly taken: then [`literal_fault`] finds no
    /// fault in it.
    pub fn take(&self, value: &Decimal) -> bool {
        let digits = value.significant_int_digits();
        let point = value.has_point();
        (self.signed || value.sign().is_none())
            && digits <= u32::from(self.int_digits[usize::from(point)])
            && !(point && self.frac_digits > 0 && value.frac_digits() > u32::from(self.frac_digits))
            && self.within[usize::from(value.is_negative())].checked_shr(digits).is_some_and(|bits| bits & 1 == 1)
    }
}

/// Whether `address` switches length corrections (`&`) and `digits` has a
/// digit other than 0, 1 or 2.
fn switches_lengths_outside_decades(address: &Address, digits: &str) -> bool {
    address.role == AddressRole::LengthCompensation && digits.bytes().any(|b| matches!(b, b'3'..=b'9'))
}

/// Whether `address` takes a parameter's raw digits (`R10=123` → `G123`)
/// rather than its value in mm: codes, counts, numbers and the feed.
pub fn takes_digits(address: &Address) -> bool {
    address.frac_digits == Some(0) || address.role == AddressRole::Feed
}

/// A parameter's raw value substituted into `address` on `machine`, when
/// the address takes its digits: more of them than it takes (the control
/// stops with "an R of more than 2 decades cannot be substituted", 02 §3.6),
/// a sign it does not take, or a value outside its range. `thread`: F is a
/// thread's lead, which a parameter gives beyond 99.99 mm (01 §6.8.5).
pub fn substitution_fault(address: &Address, raw: Raw, thread: bool, machine: &MachineConfig) -> Option<Fault> {
    if !takes_digits(address) {
        return None;
    }
    let letter = &address.letter;
    let digits = raw.unsigned_abs().to_string();
    let limit = match address.role {
        AddressRole::Feed if thread => None,
        AddressRole::Feed => address.int_digits_without_point,
        _ => address.int_digits,
    };
    if let Some(limit) = limit.filter(|&limit| digits.len() > usize::from(limit)) {
        return Some(Fault::new(
            Refusal::Digits,
            format!(
                "the parameter holds {} ({digits} as digits, {} decades) but `{letter}` takes at most {limit}: the control stops with \"an R of more than {limit} decades cannot be substituted\"",
                show(raw),
                digits.len()
            ),
        ));
    }
    if raw < 0 && !address.signed {
        return Some(Fault::new(
            Refusal::Sign,
            format!("the parameter holds {}, but `{letter}` takes only unsigned values", show(raw)),
        ));
    }
    if switches_lengths_outside_decades(address, &digits) {
        return Some(Fault::new(
            Refusal::Decade,
            format!(
                "the parameter holds {} (read as `{letter}{raw}`): each `{letter}` digit must be 0, 1 or 2",
                show(raw)
            ),
        ));
    }
    // A feed's range depends on its unit, which the feed checks know.
    let ranged = address.role != AddressRole::Feed && outside_range(address, raw as f64, machine);
    ranged.then(|| {
        Fault::new(
            Refusal::Range,
            format!(
                "the parameter holds {} (read as `{letter}{raw}`), outside `{letter}`'s range {}",
                show(raw),
                range(address)
            ),
        )
    })
}

const POWERS: [f64; 10] = [1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9];

/// Whether `digits` significant digits before the point put a value (a
/// `negative` one) within the range `bounds` whatever they are: `X12.345`
/// lies between 10 and 100. Most words are decided so, without converting
/// the number.
fn surely_within(bounds: Option<(f64, f64)>, digits: u32, negative: bool) -> bool {
    let digits = digits as usize;
    let (Some((min, max)), Some(&above)) = (bounds, POWERS.get(digits)) else { return false };
    // At least 10^(digits - 1) (or 0), below 10^digits.
    let at_least = if digits == 0 { 0.0 } else { POWERS[digits - 1] };
    let (low, high) = if negative { (-above, -at_least) } else { (at_least, above) };
    min <= low && high <= max
}

/// Whether `value` lies outside the range of `address`. `D0` is not: it
/// cancels the length corrections in length-compensation mode B (machine
/// constant 329 decade 7 = 1, 02 §1.18.1).
fn outside_range(address: &Address, value: f64, machine: &MachineConfig) -> bool {
    let cancels_length = address.role == AddressRole::Offset && value == 0.0 && machine.decade(329, 7) == 1;
    address.bounds.is_some_and(|(min, max)| !(min..=max).contains(&value)) && !cancels_length
}

/// A raw value as the real number the parameter holds (`864` → `0.864`).
pub fn show(raw: Raw) -> String {
    let sign = if raw < 0 { "-" } else { "" };
    let magnitude = raw.unsigned_abs();
    format!("{sign}{}.{:03}", magnitude / 1000, magnitude % 1000)
}

#[cfg(test)]
mod tests {
    use ncc_catalog::Dialect;
    use ncc_syntax::{Decimal, Sign};

    use super::{PlainLiterals, Refusal, assignment_fault, literal_fault, show, substitution_fault};
    use crate::machine::MachineConfig;

    fn decimal(text: &str) -> Decimal {
        let (sign, digits) = match text.strip_prefix('-') {
            Some(digits) => (Some(Sign::Minus), digits),
            None => (None, text),
        };
        Decimal::parse(sign, digits).expect("a number")
    }

    fn refusal_of_literal(letter: u8, text: &str, machine: &MachineConfig) -> Option<Refusal> {
        let address = Dialect::Cnc8x6.catalogue().address_of(letter).expect("an address");
        literal_fault(address, &decimal(text), machine).map(|fault| fault.refusal)
    }

    #[test]
    fn literals_are_held_to_their_address_format() {
        let machine = MachineConfig::default();
        let refused = |letter, text| refusal_of_literal(letter, text, &machine);
        assert_eq!(refused(b'F', "-100"), Some(Refusal::Sign));
        assert_eq!(refused(b'X', "99999999999999999999"), Some(Refusal::Digits));
        assert_eq!(refused(b'X', "1.2345"), Some(Refusal::Digits));
        assert_eq!(refused(b'X', "99999.999"), Some(Refusal::Range));
        assert_eq!(refused(b'X', "-69999.999"), None);
        assert_eq!(refused(b'F', "24000"), None);
        assert_eq!(refused(b'D', "0"), Some(Refusal::Range));
        // D0 cancels the length corrections in mode B.
        let mode_b = MachineConfig { constants: [(329, 1_000_000)].into(), ..MachineConfig::default() };
        assert_eq!(refusal_of_literal(b'D', "0", &mode_b), None);
    }

    /// The words of CAM output are plainly taken; what is not is refused
    /// or needs a closer look.
    #[test]
    fn plain_words_are_taken_at_a_glance() {
        let plain = |letter: u8, text: &str| {
            PlainLiterals::of(Dialect::Cnc8x6.catalogue().address_of(letter)).take(&decimal(text))
        };
        for (letter, text) in
            [(b'X', "12.345"), (b'Y', "-1.5"), (b'Z', "0"), (b'G', "1"), (b'F', "2400"), (b'N', "123")]
        {
            assert!(plain(letter, text), "{}{text}", char::from(letter));
        }
        for (letter, text) in [(b'X', "99999.999"), (b'X', "1.2345"), (b'F', "-100"), (b'D', "0")] {
            assert!(!plain(letter, text), "{}{text}", char::from(letter));
        }
        assert!(!PlainLiterals::of(None).take(&decimal("1")));
    }

    proptest::proptest! {
        /// What an address plainly takes, it takes: the glance agrees with
        /// the close look, on every address and in both length modes.
        #[test]
        fn a_plainly_taken_literal_has_no_fault(
            letter in 0u8..26,
            negative: bool,
            int in "[0-9]{0,12}",
            frac in proptest::option::of("[0-9]{0,6}"),
            mode_b: bool,
        ) {
            let text = match &frac {
                Some(frac) => format!("{}{int}.{frac}", if negative { "-" } else { "" }),
                None => format!("{}{int}", if negative { "-" } else { "" }),
            };
            proptest::prop_assume!(!int.is_empty() || frac.as_deref().is_some_and(|frac| !frac.is_empty()));
            let value = decimal(&text);
            let address = Dialect::Cnc8x6.catalogue().address_of(b'A' + letter);
            let machine = MachineConfig { constants: [(329, if mode_b { 1_000_000 } else { 0 })].into(), ..MachineConfig::default() };
            if PlainLiterals::of(address).take(&value) {
                let fault = address.and_then(|address| literal_fault(address, &value, &machine));
                proptest::prop_assert_eq!(fault, None, "{}{}", char::from(b'A' + letter), text);
            }
        }
    }

    #[test]
    fn assignments_stay_within_the_parameter_range() {
        let r = Dialect::Cnc8x6.catalogue().address_of(b'R').expect("R");
        let fault = assignment_fault(r, &decimal("99010203")).expect("out of range");
        assert_eq!(fault.message, "`99010203` is outside the parameter range -69999.999 to 69999.999");
        assert_eq!(assignment_fault(r, &decimal("69999999")), None);
        assert_eq!(assignment_fault(r, &decimal("123456.")).map(|fault| fault.refusal), Some(Refusal::Digits));
    }

    #[test]
    fn a_substituted_value_has_the_digits_its_address_takes() {
        let catalogue = Dialect::Cnc8x6.catalogue();
        let machine = MachineConfig::default();
        let fault = |letter, raw, thread| {
            substitution_fault(catalogue.address_of(letter).expect("an address"), raw, thread, &machine)
        };
        let overflow = fault(b'G', 123, false).expect("three digits into two");
        assert_eq!(
            overflow.message,
            "the parameter holds 0.123 (123 as digits, 3 decades) but `G` takes at most 2: the control stops with \"an R of more than 2 decades cannot be substituted\""
        );
        assert_eq!(fault(b'M', 99, false), None);
        assert_eq!(fault(b'F', 250_000, true), None);
        assert_eq!(fault(b'F', 250_000, false).map(|fault| fault.refusal), Some(Refusal::Digits));
        assert_eq!(fault(b'F', -100, false).map(|fault| fault.refusal), Some(Refusal::Sign));
        assert_eq!(fault(b'Q', 0, false).map(|fault| fault.refusal), Some(Refusal::Range));
        // Lengths take the value in mm, not digits.
        assert_eq!(fault(b'X', 99_999_999, false), None);
        assert_eq!([show(864), show(-864), show(100_000)], ["0.864", "-0.864", "100.000"]);
    }
}
