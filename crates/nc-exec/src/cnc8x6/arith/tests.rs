use super::*;

/// A machine with fixed positions and table values that records what it is told.
#[derive(Debug, Default)]
struct TestMachine {
    measured: Vec<(u8, Raw)>,
    programmed: Vec<(u8, Raw)>,
    table: Vec<((u8, u16, u16), Raw)>,
    written: Vec<(u8, u16, u16, Raw)>,
    messages: Vec<Message>,
}

fn lookup<K: PartialEq>(entries: &[(K, Raw)], key: K) -> Option<Raw> {
    entries.iter().find(|(k, _)| *k == key).map(|&(_, v)| v)
}

impl Machine for TestMachine {
    fn measured_position(&self, axis: u8) -> Option<Raw> {
        lookup(&self.measured, axis)
    }
    fn programmed_position(&self, axis: u8) -> Option<Raw> {
        lookup(&self.programmed, axis)
    }
    fn read_table(&self, table: u8, row: u16, column: u16) -> Option<Raw> {
        lookup(&self.table, (table, row, column))
    }
    fn write_table(&mut self, table: u8, row: u16, column: u16, value: Raw) {
        self.written.push((table, row, column, value));
    }
    fn message(&mut self, message: Message) {
        self.messages.push(message);
    }
}

/// A value as a declaration stores it: `R1=864` → 864, `R1=864.` → 864000.
fn r(text: &str) -> Raw {
    match text.split_once('.') {
        None => text.parse().unwrap(),
        Some((int, frac)) => {
            let magnitude = int.trim_start_matches(['-', '+']).parse::<Raw>().unwrap_or(0) * 1000
                + format!("{frac:0<3}").parse::<Raw>().unwrap();
            if int.starts_with('-') { -magnitude } else { magnitude }
        }
    }
}

fn word(text: &str) -> ControlWord {
    ControlWord::decode(text.parse().unwrap()).unwrap()
}

/// Zeroed parameters with some declared.
fn params(values: &[(usize, &str)]) -> Parameters {
    let mut p = Parameters::zeroed();
    for &(n, value) in values {
        p.set(n, Some(r(value)));
    }
    p
}

fn run_with(
    p: &mut Parameters,
    texts: &[&str],
    machine: &mut dyn Machine,
    config: ArithConfig,
) -> Result<(), (usize, ArithError)> {
    let words: Vec<_> = texts.iter().map(|t| word(t)).collect();
    execute(&words, p, machine, config)
}

fn run(p: &mut Parameters, texts: &[&str]) -> Result<(), (usize, ArithError)> {
    run_with(p, texts, &mut UnknownMachine, ArithConfig::default())
}

const DOUBLE: ArithConfig = ArithConfig { double_precision: true };

/// Runs one word and returns its target.
fn result(values: &[(usize, &str)], text: &str) -> Option<Raw> {
    let mut p = params(values);
    run(&mut p, &[text]).unwrap();
    p.get(usize::from(word(text).target))
}

fn error(values: &[(usize, &str)], text: &str) -> ArithError {
    error_with(values, text, ArithConfig::default())
}

fn error_with(values: &[(usize, &str)], text: &str, config: ArithConfig) -> ArithError {
    let mut p = params(values);
    run_with(&mut p, &[text], &mut UnknownMachine, config).unwrap_err().1
}

fn field(field: &'static str, value: u8) -> ArithError {
    ArithError::FieldOutOfRange { field, value }
}

#[test]
fn decodes_sign_and_fields() {
    assert_eq!(word("-42120212"), ControlWord { integer: true, op: 42, op1: 12, op2: 2, target: 12 });
    assert_eq!(word("19141706"), ControlWord { integer: false, op: 19, op1: 14, op2: 17, target: 6 });
    assert_eq!(word("+00280039"), ControlWord { integer: false, op: 0, op1: 28, op2: 0, target: 39 });
    assert_eq!(ControlWord::decode(99_999_999).unwrap().op, 99);
    // `R5=15313024.` stores 15313024000.
    assert_eq!(ControlWord::decode(15_313_024_000), Err(ArithError::ControlWordTooLong(15_313_024_000)));
    assert!(ControlWord::decode(Raw::MIN).is_err());
}

#[test]
fn copy_add_subtract_absolute_negate_ignore_the_sign() {
    for sign in ["", "+", "-"] {
        let w = |body: &str| format!("{sign}{body}");
        assert_eq!(result(&[(13, "3")], &w("00130019")), Some(3));
        assert_eq!(result(&[(29, "10."), (24, "1.000")], &w("01292425")), Some(11_000));
        assert_eq!(result(&[(29, "10."), (28, "12.")], &w("02292829")), Some(-2_000));
        assert_eq!(result(&[(46, "5.5")], &w("02464646")), Some(0));
        assert_eq!(result(&[(28, "-12.")], &w("07280028")), Some(12_000));
        assert_eq!(result(&[(10, "100.0")], &w("08100010")), Some(-100_000));
    }
}

#[test]
fn multiply_real_and_integer() {
    // The manual's R12 = 0.004 (declared `4`) times R10 = 100.000.
    assert_eq!(result(&[(12, "4"), (10, "100.0")], "03121015"), Some(400));
    assert_eq!(result(&[(12, "4"), (10, "100.0")], "-03121015"), Some(400_000));
    // 1.005 · 0.5 = 0.5025: halves round away from zero.
    assert_eq!(result(&[(1, "1.005"), (2, "0.5")], "03010203"), Some(503));
    assert_eq!(result(&[(1, "-1.005"), (2, "0.5")], "03010203"), Some(-503));
}

#[test]
fn divide_real_and_integer() {
    assert_eq!(result(&[(1, "10."), (2, "4.")], "04010203"), Some(2_500));
    assert_eq!(result(&[(1, "2."), (2, "3.")], "04010203"), Some(667));
    assert_eq!(result(&[(1, "10"), (2, "4")], "-04010203"), Some(2));
    assert_eq!(result(&[(1, "-7"), (2, "2")], "-04010203"), Some(-3));
    assert_eq!(error(&[(1, "1.")], "04010203"), ArithError::DivisionByZero);
    assert_eq!(error(&[(1, "1")], "-04010203"), ArithError::DivisionByZero);
}

#[test]
fn square_and_square_root() {
    assert_eq!(result(&[(10, "3.")], "05100011"), Some(9_000));
    // 0.004² = 0.000016, below a thousandth.
    assert_eq!(result(&[(10, "4")], "05100011"), Some(0));
    assert_eq!(result(&[(10, "4")], "-05100011"), Some(16));
    assert_eq!(result(&[(10, "2.")], "06100011"), Some(1_414));
    assert_eq!(result(&[(10, "2.25")], "06100011"), Some(1_500));
    assert_eq!(result(&[(10, "4")], "-06100011"), Some(2));
    assert_eq!(result(&[(10, "8")], "-06100011"), Some(2));
    assert_eq!(error(&[(10, "-1.")], "06100011"), ArithError::NegativeSquareRoot);
    assert_eq!(error(&[(10, "-4")], "-06100011"), ArithError::NegativeSquareRoot);
}

#[test]
fn binary_shift() {
    // Lathe G84: R32 = -1 (declared without a point) halves the chip in diameter programming.
    for sign in ["", "-"] {
        assert_eq!(result(&[(46, "0.446"), (32, "-1")], &format!("{sign}09463242")), Some(223));
    }
    assert_eq!(result(&[(46, "0.446"), (32, "0")], "09463242"), Some(446));
    assert_eq!(result(&[(46, "0.446"), (32, "3")], "09463242"), Some(3_568));
    assert_eq!(result(&[(46, "-0.445"), (32, "-1")], "09463242"), Some(-223));
    assert_eq!(result(&[(46, "5."), (32, "-32")], "09463242"), Some(0));
    assert_eq!(error(&[(32, "33")], "09463242"), ArithError::ShiftOutOfRange { count: 33, limit: 32 });
    assert_eq!(error(&[(46, "1."), (32, "20")], "09463242"), ArithError::Overflow);
    // A pair may shift by up to 64 places.
    let mut p = params(&[(40, "1"), (32, "40")]);
    run_with(&mut p, &["09903292"], &mut UnknownMachine, DOUBLE).unwrap();
    assert_eq!((p.get(42), p.get(43)), (Some(0), Some(256)));
    assert_eq!(error_with(&[(32, "65")], "09903292", DOUBLE), ArithError::ShiftOutOfRange { count: 65, limit: 64 });
}

#[test]
fn reciprocal() {
    assert_eq!(result(&[(10, "4.")], "10100011"), Some(250));
    assert_eq!(result(&[(10, "-3.")], "10100011"), Some(-333));
    assert_eq!(result(&[(10, "1")], "-10100011"), Some(1));
    assert_eq!(result(&[(10, "4")], "-10100011"), Some(0));
    assert_eq!(error(&[], "10100011"), ArithError::DivisionByZero);
}

#[test]
fn power_of_two_logarithm_and_power_are_real_only() {
    assert_eq!(result(&[(10, "10.")], "11100011"), Some(1_024_000));
    assert_eq!(result(&[(10, "0.5")], "11100011"), Some(1_414));
    assert_eq!(result(&[(10, "-1.")], "11100011"), Some(500));
    assert_eq!(error(&[(10, "100.")], "11100011"), ArithError::Overflow);
    assert_eq!(result(&[(10, "8.")], "12100011"), Some(3_000));
    assert_eq!(result(&[(10, "0.5")], "12100011"), Some(-1_000));
    assert_eq!(error(&[], "12100011"), ArithError::LogOfNonPositive);
    assert_eq!(error(&[(10, "-2.")], "12100011"), ArithError::LogOfNonPositive);
    assert_eq!(result(&[(10, "2."), (11, "3.")], "13101112"), Some(8_000));
    assert_eq!(result(&[(10, "-2."), (11, "3.")], "13101112"), Some(-8_000));
    assert_eq!(result(&[(10, "4."), (11, "0.5")], "13101112"), Some(2_000));
    assert_eq!(error(&[(10, "-2."), (11, "0.5")], "13101112"), ArithError::PowerDomain);
    assert_eq!(error(&[(11, "-1.")], "13101112"), ArithError::PowerDomain);
    for op in ["11100011", "12100011", "13101112", "27100011", "28283940"] {
        let code = word(op).op;
        assert_eq!(error(&[], &format!("-{op}")), ArithError::IntegerModeNotAllowed(code));
    }
}

#[test]
fn double_precision_is_refused_where_the_manual_forbids_it() {
    let refused = |text: &str, field| {
        let op = word(text).op;
        assert_eq!(error_with(&[], text, DOUBLE), ArithError::DoublePrecisionNotAllowed { op, field });
    };
    refused("11600011", "op1");
    refused("12100061", "target");
    refused("13601112", "op1");
    refused("13106112", "op2");
    refused("27600011", "op1");
    refused("28783940", "op1");
    refused("28288940", "op2");
    // Without double precision the same fields are plain parameters.
    assert_eq!(result(&[(60, "3.")], "11600011"), Some(8_000));
}

#[test]
fn root_of_the_sum_of_squares() {
    assert_eq!(result(&[(10, "3."), (11, "4.")], "14101112"), Some(5_000));
    assert_eq!(result(&[(10, "1."), (11, "1.")], "14101112"), Some(1_414));
    assert_eq!(result(&[(10, "3"), (11, "4")], "-14101112"), Some(5));
    assert_eq!(result(&[(10, "1"), (11, "1")], "-14101112"), Some(1));
}

#[test]
fn comparisons_store_raw_73_or_78() {
    // (op, a < b, a = b, a > b)
    let cases = [(15, 78, 78, 73), (16, 78, 73, 73), (17, 73, 78, 78), (18, 73, 73, 78), (19, 78, 73, 78)];
    for (op, less, equal, greater) in cases {
        for sign in ["", "-"] {
            let text = format!("{sign}{op}010203");
            assert_eq!(result(&[(1, "1."), (2, "2.")], &text), Some(less), "{text}");
            assert_eq!(result(&[(1, "2."), (2, "2.")], &text), Some(equal), "{text}");
            assert_eq!(result(&[(1, "3."), (2, "2.")], &text), Some(greater), "{text}");
        }
    }
}

#[test]
fn conditions_skip_up_to_op_22() {
    // (op, holds for a < b, a = b, a > b)
    let cases = [
        (20, false, true, false),
        (21, true, false, true),
        (29, false, false, true),
        (30, false, true, true),
        (31, true, false, false),
        (32, true, true, false),
    ];
    for (op, less, equal, greater) in cases {
        for (a, holds) in [("1.", less), ("2.", equal), ("3.", greater)] {
            let mut p = params(&[(1, a), (2, "2."), (8, "5."), (9, "6.")]);
            let condition = format!("{op}010200");
            run(&mut p, &[&condition, "00080010", "22000000", "00090011"]).unwrap();
            assert_eq!(p.get(10), Some(if holds { 5_000 } else { 0 }), "{condition} with R1 = {a}");
            assert_eq!(p.get(11), Some(6_000), "op 22 ends the condition");
        }
    }
}

#[test]
fn a_failed_condition_without_op_22_skips_the_rest_and_op_22_ends_all() {
    let mut p = params(&[(1, "1")]);
    run(&mut p, &["20010000", "00010010", "00010011"]).unwrap();
    assert_eq!((p.get(10), p.get(11)), (Some(0), Some(0)));
    // A condition met while skipping is skipped; one 22 ends both.
    let mut p = params(&[(1, "1")]);
    run(&mut p, &["20010000", "20000000", "00010010", "22000000", "00010011"]).unwrap();
    assert_eq!((p.get(10), p.get(11)), (Some(0), Some(1)));
    // Two conditions in a row must both hold.
    let mut p = params(&[(1, "1")]);
    run(&mut p, &["21010000", "20000000", "00010010", "22000000"]).unwrap();
    assert_eq!(p.get(10), Some(1));
    // Op 22 without a condition does nothing.
    assert!(run(&mut params(&[]), &["22000000"]).is_ok());
}

#[test]
fn integer_real_conversion() {
    assert_eq!(result(&[(29, "5")], "+23290039"), Some(5_000));
    assert_eq!(result(&[(29, "5")], "-23290039"), Some(5_000));
    assert_eq!(error(&[(29, "70000")], "23290039"), ArithError::Overflow);
    assert_eq!(result(&[(10, "5.999")], "24100011"), Some(5));
    assert_eq!(result(&[(10, "-2.5")], "24100011"), Some(-2));
}

#[test]
fn axis_positions() {
    let mut machine = TestMachine {
        measured: vec![(1, r("12.5"))],
        programmed: vec![(1, r("64.")), (2, r("4."))],
        ..TestMachine::default()
    };
    let mut p = params(&[]);
    run_with(&mut p, &["25010030", "26020031"], &mut machine, ArithConfig::default()).unwrap();
    assert_eq!((p.get(30), p.get(31)), (Some(12_500), Some(4_000)));
    // A pair target takes axis op1 into its first and axis op2 into its second parameter.
    run_with(&mut p, &["+26010283"], &mut machine, DOUBLE).unwrap();
    assert_eq!((p.get(33), p.get(34)), (Some(64_000), Some(4_000)));
    // An axis without a known position gives an unknown value.
    run_with(&mut p, &["25030030"], &mut machine, ArithConfig::default()).unwrap();
    assert_eq!(p.get(30), None);
    assert_eq!(error(&[], "25070030"), field("op1", 7));
    assert_eq!(error(&[], "26000030"), field("op1", 0));
    assert_eq!(error_with(&[], "26010083", DOUBLE), field("op2", 0));
}

#[test]
fn tangent_in_degrees() {
    assert_eq!(result(&[(10, "45.")], "27100011"), Some(1_000));
    assert_eq!(result(&[(10, "135.")], "27100011"), Some(-1_000));
    assert_eq!(result(&[(10, "-45.")], "27100011"), Some(-1_000));
    assert_eq!(result(&[(10, "89.999")], "27100011"), Some(57_295_780));
    assert_eq!(error(&[(10, "90.")], "27100011"), ArithError::TangentUndefined);
    assert_eq!(error(&[(10, "-270.")], "27100011"), ArithError::TangentUndefined);
}

#[test]
fn geometric_series() {
    // Lathe G84: quotient 0.8, five chips: 1 + 0.8 + 0.64 + 0.512 + 0.4096 = 3.3616.
    assert_eq!(result(&[(28, "0.8"), (39, "5.")], "+28283940"), Some(3_362));
    assert_eq!(result(&[(28, "1."), (39, "4.")], "+28283940"), Some(4_000));
    assert_eq!(result(&[(28, "2."), (39, "0")], "+28283940"), Some(0));
    // A count declared without a point must be converted with op 23 first.
    assert_eq!(error(&[(28, "0.8"), (39, "5")], "+28283940"), ArithError::SeriesTermCount);
    assert_eq!(error(&[(28, "0.8"), (39, "-1.")], "+28283940"), ArithError::SeriesTermCount);
}

#[test]
fn sine_and_cosine_times_ten_million() {
    assert_eq!(result(&[(10, "30.")], "37100011"), Some(5_000_000));
    assert_eq!(result(&[(10, "90.")], "37100011"), Some(10_000_000));
    assert_eq!(result(&[(10, "-390.")], "37100011"), Some(-5_000_000));
    assert_eq!(result(&[(10, "60.")], "38100011"), Some(5_000_000));
    assert_eq!(result(&[(10, "180.")], "38100011"), Some(-10_000_000));
    // Integer mode reads the angle as whole degrees.
    assert_eq!(result(&[(10, "30")], "-37100011"), Some(5_000_000));
    assert_eq!(result(&[(10, "30")], "37100011"), Some(5_236));
}

#[test]
fn arc_sine_of_a_ratio() {
    assert_eq!(result(&[(10, "1."), (11, "2.")], "39101112"), Some(30_000));
    assert_eq!(result(&[(10, "-1."), (11, "1.")], "39101112"), Some(-90_000));
    assert_eq!(result(&[(10, "1"), (11, "2")], "-39101112"), Some(30));
    assert_eq!(error(&[(10, "3."), (11, "2.")], "39101112"), ArithError::ArcsinDomain);
    assert_eq!(error(&[(10, "1.")], "39101112"), ArithError::DivisionByZero);
}

#[test]
fn increment_and_decrement_take_an_immediate() {
    assert_eq!(result(&[(20, "2")], "-41200020"), Some(3));
    assert_eq!(result(&[(20, "2")], "-41200320"), Some(5));
    assert_eq!(result(&[(20, "2")], "41200020"), Some(1_002));
    assert_eq!(result(&[(12, "4")], "41120212"), Some(2_004));
    assert_eq!(result(&[(12, "4")], "-42120212"), Some(2));
    assert_eq!(result(&[(13, "3")], "-42130013"), Some(2));
    // The manual's warning: with `+` the count 0.004 loses 2.000.
    assert_eq!(result(&[(12, "4")], "42120212"), Some(-1_996));
}

#[test]
fn undefined_and_undocumented_operations() {
    for op in std::iter::once(43).chain(52..=99) {
        assert_eq!(error(&[], &format!("{op}000000")), ArithError::UndefinedOperation(op));
    }
    for op in [36, 40] {
        assert_eq!(error(&[], &format!("{op}000000")), ArithError::UndocumentedOperation(op));
    }
}

#[test]
fn move_parameters() {
    let mut p = params(&[(10, "1"), (11, "2"), (12, "3")]);
    run(&mut p, &["34101230"]).unwrap();
    assert_eq!([p.get(30), p.get(31), p.get(32), p.get(10)], [Some(1), Some(2), Some(3), Some(1)]);
    // Overlapping ranges move as if through a buffer.
    run(&mut p, &["34101211"]).unwrap();
    assert_eq!([p.get(11), p.get(12), p.get(13)], [Some(1), Some(2), Some(3)]);
    // op1 = 99 clears target … op2.
    let mut p = params(&[(29, "1"), (30, "1"), (40, "1"), (41, "1")]);
    run(&mut p, &["34994030"]).unwrap();
    assert_eq!([p.get(29), p.get(30), p.get(40), p.get(41)], [Some(1), Some(0), Some(0), Some(1)]);
    assert_eq!(error(&[], "34121030"), ArithError::InvalidRange { first: 12, last: 10 });
    assert_eq!(error(&[], "34993040"), ArithError::InvalidRange { first: 40, last: 30 });
    assert_eq!(error(&[], "34101294"), ArithError::RangePastEnd);
    assert_eq!(error(&[], "34109630"), field("op2", 96));
    // The fields name parameters directly, even with double precision on.
    let mut p = params(&[(60, "7")]);
    run_with(&mut p, &["34606070"], &mut UnknownMachine, DOUBLE).unwrap();
    assert_eq!(p.get(70), Some(7));
}

#[test]
fn exchange_parameters() {
    let mut p = params(&[(10, "1"), (11, "2"), (30, "3"), (31, "4")]);
    run(&mut p, &["35101130"]).unwrap();
    assert_eq!([p.get(10), p.get(11), p.get(30), p.get(31)], [Some(3), Some(4), Some(1), Some(2)]);
    assert_eq!(error(&[], "35101211"), ArithError::OverlappingRanges);
    assert_eq!(error(&[], "35101210"), ArithError::OverlappingRanges);
    assert_eq!(error(&[], "35101294"), ArithError::RangePastEnd);
}

#[test]
fn save_and_restore() {
    let mut p = params(&[(10, "1"), (11, "2"), (12, "3")]);
    run(&mut p, &["44000000", "34991210", "00000095"]).unwrap();
    assert_eq!([p.get(10), p.get(11), p.get(12)], [Some(0); 3]);
    // A range: saved R10 … R11 into R20 … R21.
    run(&mut p, &["45101120"]).unwrap();
    assert_eq!([p.get(20), p.get(21), p.get(10)], [Some(1), Some(2), Some(0)]);
    // Everything, and again: RESTORE keeps the copy.
    run(&mut p, &["45000000"]).unwrap();
    assert_eq!([p.get(10), p.get(11), p.get(12), p.get(20)], [Some(1), Some(2), Some(3), Some(0)]);
    p.set(10, Some(9));
    run(&mut p, &["45000000"]).unwrap();
    assert_eq!(p.get(10), Some(1));
    assert_eq!(error(&[], "45000000"), ArithError::RestoreWithoutSave);
    assert_eq!(error(&[], "45101120"), ArithError::RestoreWithoutSave);
    let mut p = params(&[]);
    assert_eq!(run(&mut p, &["44000000", "45109590"]), Err((1, ArithError::RangePastEnd)));
}

#[test]
fn parity() {
    assert_eq!(result(&[(19, "3")], "46190017"), Some(73));
    assert_eq!(result(&[(19, "3")], "47190017"), Some(78));
    assert_eq!(result(&[(19, "4")], "46190017"), Some(78));
    assert_eq!(result(&[(19, "4")], "47190017"), Some(73));
    assert_eq!(result(&[(19, "-3")], "46190017"), Some(73));
}

#[test]
fn logic_on_decades() {
    // The manual's switch of double precision: SET and CLR decade 1 of R95.
    assert_eq!(result(&[(95, "0")], "48110095"), Some(1));
    assert_eq!(result(&[(95, "11")], "48210095"), Some(10));
    let mut p = params(&[]);
    run_with(&mut p, &["48110095"], &mut UnknownMachine, DOUBLE).unwrap();
    assert_eq!(p.get(95), Some(1));
    assert_eq!(result(&[(20, "12345")], "48130020"), Some(12_145));
    assert_eq!(result(&[(20, "-5")], "48120020"), Some(-15));
    // NOT treats a digit as a bit.
    assert_eq!(result(&[(20, "105")], "48320020"), Some(115));
    assert_eq!(result(&[(20, "175")], "48320020"), Some(105));
    // OR, AND, XOR: decade 2 of R30 with decade 2 of R20, into R20.
    assert_eq!(result(&[(30, "10"), (20, "100")], "48423020"), Some(110));
    assert_eq!(result(&[(30, "10"), (20, "110")], "48523020"), Some(110));
    assert_eq!(result(&[(30, "0"), (20, "110")], "48523020"), Some(100));
    assert_eq!(result(&[(30, "10"), (20, "110")], "48623020"), Some(100));
    assert_eq!(result(&[(30, "10"), (20, "100")], "48623020"), Some(110));
    // TEST: 73 when decade 2 of R30 is set.
    assert_eq!(result(&[(30, "10")], "48723020"), Some(73));
    assert_eq!(result(&[(30, "105")], "48723020"), Some(78));
    assert_eq!(error(&[], "48810095"), field("logic operation", 8));
    assert_eq!(error(&[], "48190095"), field("decade", 9));
    assert_eq!(error(&[], "48100095"), field("decade", 0));
    assert_eq!(error(&[], "48110096"), field("target", 96));
    assert_eq!(error(&[], "48419620"), field("operand", 96));
}

#[test]
fn read_from_tables() {
    let mut machine = TestMachine {
        table: vec![((5, 2, 1), 3), ((3, 339, 0), 1234), ((1, 12, 2), r("5.5")), ((2, 54, 1), r("-20."))],
        ..TestMachine::default()
    };
    let mut p = params(&[]);
    run_with(&mut p, &["49510224", "49333925", "49121226", "49215427"], &mut machine, ArithConfig::default()).unwrap();
    assert_eq!([p.get(24), p.get(25), p.get(26), p.get(27)], [Some(3), Some(1234), Some(5_500), Some(-20_000)]);
    // Nothing known there.
    run_with(&mut p, &["49110124"], &mut machine, ArithConfig::default()).unwrap();
    assert_eq!(p.get(24), None);
    assert_eq!(error(&[], "49610224"), field("table", 6));
    assert_eq!(error(&[], "49110024"), field("correction entry", 0));
    assert_eq!(error(&[], "49215224"), field("offset", 52));
    assert_eq!(error(&[], "49590224"), field("column", 9));
    assert_eq!(error(&[], "49200224"), field("offset", 2));
    assert_eq!(error(&[], "49510296"), field("target", 96));
}

#[test]
fn write_to_tables() {
    let mut machine = TestMachine::default();
    let mut p = params(&[(30, "2.5")]);
    run_with(&mut p, &["50113012", "50223055"], &mut machine, ArithConfig::default()).unwrap();
    assert_eq!(machine.written, [(1, 12, 1, 2_500), (2, 55, 2, 2_500)]);
    // An unknown value is not written.
    p.set(30, None);
    run_with(&mut p, &["50113012"], &mut machine, ArithConfig::default()).unwrap();
    assert_eq!(machine.written.len(), 2);
    assert_eq!(error(&[], "50313012"), field("table", 3));
    assert_eq!(error(&[], "50103012"), field("column", 0));
    assert_eq!(error(&[], "50113000"), field("correction entry", 0));
    assert_eq!(error(&[], "50213060"), field("offset", 60));
}

#[test]
fn messages() {
    let mut machine = TestMachine::default();
    let mut p = params(&[(30, "12.5")]);
    let texts = ["51073053", "51073050", "51073051", "51073052"];
    run_with(&mut p, &texts, &mut machine, ArithConfig::default()).unwrap();
    let displays: Vec<_> = machine.messages.iter().map(|m| m.display).collect();
    assert_eq!(
        displays,
        [MessageDisplay::Seconds(5), MessageDisplay::Cancel, MessageDisplay::Permanent, MessageDisplay::OneBlock]
    );
    assert_eq!(
        machine.messages[0],
        Message { code: 7, parameter: 30, value: Some(12_500), display: MessageDisplay::Seconds(5) }
    );
    assert_eq!(error(&[], "51003051"), field("message code", 0));
    assert_eq!(error(&[], "51073054"), field("display mode", 4));
    assert_eq!(error(&[], "51073003"), field("display time", 0));
    assert_eq!(error(&[], "51079651"), field("op2", 96));
}

#[test]
fn program_runs_the_words_held_in_parameters() {
    // Milling G84: read the spindle direction (M group 2 of AWRK) and choose the reverse one.
    for (spindle, reverse) in [(3, 4), (4, 3)] {
        let mut machine = TestMachine { table: vec![((5, 2, 1), spindle)], ..TestMachine::default() };
        let mut p = params(&[
            (8, "4"),
            (9, "3"),
            (10, "49510220"),
            (11, "20200900"),
            (12, "00080007"),
            (13, "22000000"),
            (14, "20200800"),
            (15, "00090007"),
            (16, "22000000"),
        ]);
        run_with(&mut p, &["33100016"], &mut machine, ArithConfig::default()).unwrap();
        assert_eq!((p.get(20), p.get(7)), (Some(spindle), Some(reverse)));
    }
}

#[test]
fn program_words_are_decoded_as_they_run() {
    // R10 writes the word that R11 then runs: R11 := R20 (= "00010012", R12 := R1).
    let mut p = params(&[(1, "5"), (10, "00200011"), (11, "22000000"), (20, "00010012")]);
    run(&mut p, &["33100011"]).unwrap();
    assert_eq!(p.get(12), Some(5));
}

#[test]
fn program_errors() {
    // The failing word is reported at the op 33, naming its parameter.
    let mut p = params(&[(10, "00010002"), (11, "04010203")]);
    let in_r11 = |error| ArithError::InProgram { parameter: 11, error: Box::new(error) };
    assert_eq!(run(&mut p, &["00000000", "33100011"]), Err((1, in_r11(ArithError::DivisionByZero))));
    let mut p = params(&[(10, "12345678."), (11, "01000000")]);
    assert_eq!(
        run(&mut p, &["33100011"]),
        Err((
            0,
            ArithError::InProgram { parameter: 10, error: Box::new(ArithError::ControlWordTooLong(r("12345678."))) }
        ))
    );
    // Nothing may follow op 33, in a block or in a program.
    assert_eq!(run(&mut params(&[]), &["33100011", "00000000"]), Err((0, ArithError::OperationAfterProgram)));
    let mut p = params(&[(10, "33200020"), (11, "00000000")]);
    assert_eq!(
        run(&mut p, &["33100011"]),
        Err((0, ArithError::InProgram { parameter: 10, error: Box::new(ArithError::OperationAfterProgram) }))
    );
    assert_eq!(error(&[], "33110010"), ArithError::InvalidRange { first: 11, last: 10 });
    assert_eq!(error(&[], "33100096"), field("target", 96));
    // A program that starts itself without end.
    let mut p = params(&[(10, "41200020"), (11, "33100011")]);
    assert_eq!(run(&mut p, &["33100011"]), Err((0, ArithError::ProgramLoop)));
    assert_eq!(p.get(20), Some(r("1000.")), "each of the programs ran once");
}

#[test]
fn a_program_may_start_another_as_its_last_word() {
    // A counting loop: R20 += 1 while R20 < R21.
    let mut p = params(&[(10, "-41200020"), (11, "31202100"), (12, "33100012"), (21, "5")]);
    run(&mut p, &["33100012"]).unwrap();
    assert_eq!(p.get(20), Some(5));
}

#[test]
fn unknown_operands_give_unknown_targets() {
    let mut p = params(&[]);
    p.set(1, None);
    run(&mut p, &["01010203", "15010204", "-42010005", "00020006"]).unwrap();
    assert_eq!([p.get(3), p.get(4), p.get(5), p.get(6)], [None, None, None, Some(0)]);
    // Field errors are found even when the values are unknown.
    let mut p = Parameters::unknown();
    assert_eq!(run(&mut p, &["04979899"]), Err((0, field("op1", 97))));
    assert_eq!(run(&mut p, &["04010200"]), Ok(()));
}

#[test]
fn an_unknown_condition_joins_both_outcomes() {
    let mut p = params(&[(3, "7"), (5, "8")]);
    p.set(1, None);
    // IF R1 = R2: R10 := R3, R12 := R3 ENDIF; R13 := R5.
    p.set(12, Some(7));
    run(&mut p, &["20010200", "00030010", "00030012", "22000000", "00050013"]).unwrap();
    assert_eq!(p.get(10), None, "0 if the condition fails, 7 if it holds");
    assert_eq!(p.get(12), Some(7), "7 either way");
    assert_eq!(p.get(13), Some(8), "after op 22 the outcome is known again");
    // Without op 22 the join happens at the end of the block.
    let mut p = params(&[(3, "7")]);
    p.set(1, None);
    run(&mut p, &["31010200", "00030010"]).unwrap();
    assert_eq!(p.get(10), None);
    // A known failing condition inside an unknown one.
    let mut p = params(&[(3, "7")]);
    p.set(1, None);
    run(&mut p, &["20010200", "00030010", "21000000", "00030011", "22000000"]).unwrap();
    assert_eq!((p.get(10), p.get(11)), (None, Some(0)));
}

#[test]
fn unknown_program_words() {
    // A program word that is not known may do anything.
    let mut p = params(&[(1, "5"), (10, "00010002")]);
    p.set(11, None);
    run(&mut p, &["33100011"]).unwrap();
    assert_eq!((p.get(1), p.get(2)), (None, None));
    // A loop kept going by an unknown condition ends with everything unknown, not an error.
    let mut p = params(&[(10, "-41200020"), (11, "31202100"), (12, "33100012")]);
    p.set(21, None);
    run(&mut p, &["33100012"]).unwrap();
    assert_eq!(p.get(20), None);
    // PROGRAM inside an unknown condition: the path where it fails ends there.
    let mut p = params(&[(10, "00030004"), (3, "9")]);
    p.set(1, None);
    run(&mut p, &["20010200", "33100010"]).unwrap();
    assert_eq!((p.get(4), p.get(3)), (None, Some(9)));
}

#[test]
fn double_precision_pairs() {
    // Fields 96–99 exist only as pairs.
    assert_eq!(error(&[], "00970010"), field("op1", 97));
    assert_eq!(error(&[], "00100099"), field("target", 99));
    // Lathe cycles: `R08=+00800085` copies R30, R31 into R35, R36, whatever they hold.
    let mut p = params(&[(30, "-70."), (31, "-100.")]);
    run_with(&mut p, &["+00800085"], &mut UnknownMachine, DOUBLE).unwrap();
    assert_eq!((p.get(35), p.get(36)), (Some(-70_000), Some(-100_000)));
    // A 64-bit value: low 32 bits first, high 32 bits second.
    let mut p = params(&[(1, "60000."), (2, "60000.")]);
    run_with(&mut p, &["-03010250"], &mut UnknownMachine, DOUBLE).unwrap();
    let product: Raw = 60_000_000 * 60_000_000;
    assert_eq!((p.get(0), p.get(1)), (Some(Raw::from(product as i32)), Some(product >> 32)));
    run_with(&mut p, &["-04500260"], &mut UnknownMachine, DOUBLE).unwrap();
    assert_eq!((p.get(10), p.get(11)), (Some(60_000_000), Some(0)));
    // A value that fits 32 bits reads back from the first parameter.
    let mut p = params(&[(1, "-5.")]);
    run_with(&mut p, &["00010060"], &mut UnknownMachine, DOUBLE).unwrap();
    assert_eq!((p.get(10), p.get(11)), (Some(-5_000), Some(-1)));
    // With one half unknown the pair is unknown.
    p.set(11, None);
    run_with(&mut p, &["00600001"], &mut UnknownMachine, DOUBLE).unwrap();
    assert_eq!(p.get(1), None);
    let mut p = params(&[]);
    p.set(11, Some(1 << 40));
    assert_eq!(
        run_with(&mut p, &["00600001"], &mut UnknownMachine, DOUBLE),
        Err((0, ArithError::NotADoubleHalf { parameter: 11, value: 1 << 40 }))
    );
}

#[test]
fn results_must_fit_the_parameter_range() {
    assert_eq!(result(&[(1, "69999.998"), (2, "0.001")], "01010203"), Some(MAX_RAW));
    assert_eq!(error(&[(1, "69999.999"), (2, "0.001")], "01010203"), ArithError::Overflow);
    assert_eq!(error(&[(1, "-69999.999"), (2, "0.001")], "02010203"), ArithError::Overflow);
    assert_eq!(error(&[(1, "300."), (2, "300.")], "03010203"), ArithError::Overflow);
    // A pair holds more.
    let mut p = params(&[(1, "69999.999"), (2, "0.001")]);
    run_with(&mut p, &["01010253"], &mut UnknownMachine, DOUBLE).unwrap();
    assert_eq!((p.get(3), p.get(4)), (Some(70_000_000), Some(0)));
}

#[test]
fn the_failing_word_is_reported_with_its_index() {
    let mut p = params(&[(1, "1")]);
    assert_eq!(run(&mut p, &["00010002", "00010003", "04010004"]), Err((2, ArithError::DivisionByZero)));
    assert_eq!((p.get(2), p.get(3)), (Some(1), Some(1)), "earlier words keep their effects");
}

/// Spec 02 §5.7: macro L9001 drills a grid of 4 × 3 holes by rows.
#[test]
fn worked_example_l9001() {
    let mut p = params(&[(9, "81"), (10, "100.0"), (11, "75.0"), (12, "4"), (13, "3"), (14, "0")]);
    let block = |p: &mut Parameters, texts: &[&str]| run(p, texts).unwrap();
    // N10: auxiliary parameters.
    for (n, value) in [(15, "0"), (16, "0"), (17, "0"), (18, "31"), (19, "0"), (20, "0")] {
        p.set(n, Some(r(value)));
    }
    // N20: R14 = R17 (0) → R06 = 73, so `N30 GR06 L1105` jumps to drilling by rows.
    block(&mut p, &["19141706"]);
    assert_eq!(p.get(6), Some(73));
    // N1105 G29: save everything, R19 := rows, R12 := R12 − 2, R13 := R13 − 1 (raw integers).
    block(&mut p, &["44000000", "00130019", "-42120212", "-42130113"]);
    assert_eq!([p.get(19), p.get(12), p.get(13)], [Some(3), Some(2), Some(2)]);
    let mut rows = 0;
    loop {
        rows += 1;
        // N1110–N1120: the hole loop runs R12 + 1 times, comparing the row counter each time.
        for _ in 0..=p.get(12).unwrap() {
            block(&mut p, &["19201321"]);
        }
        // N1140 GR21 L1170: all rows done?
        if p.get(21) == Some(73) {
            break;
        }
        // N1160: reverse X, count the row.
        block(&mut p, &["08100010", "-41200020"]);
        assert_eq!(p.get(10), Some(if rows % 2 == 1 { -100_000 } else { 100_000 }));
    }
    assert_eq!((rows, p.get(20)), (3, Some(2)));
    // N1170: three rows are odd, so R17 = 78 and `N1185 GR17 L1200` does not jump.
    block(&mut p, &["47190017"]);
    assert_eq!(p.get(17), Some(78));
    p.set(15, Some(0));
    // N1190: R12 := R12 + 1 = 3 column pitches, R15 := 3 · 100.000, negated.
    block(&mut p, &["-41120012", "-03121015", "08150015"]);
    assert_eq!((p.get(12), p.get(15)), (Some(3), Some(-300_000)));
    // N1200: R14 := 2 · 75.000, negated: the return is X −300, Y −150.
    block(&mut p, &["-03131114", "08140014"]);
    assert_eq!(p.get(14), Some(-150_000));
    // N1230: restore all 96 parameters as saved in N1105.
    block(&mut p, &["45000000"]);
    let restored = [(6, 73), (10, 100_000), (12, 4), (13, 3), (14, 0), (15, 0), (17, 0), (19, 0), (20, 0)];
    for (n, value) in restored {
        assert_eq!(p.get(n), Some(value), "R{n}");
    }
}

/// Spec 03 §2.1.3, milling G83 (deep drilling, minus direction), against the trace of Appendix B.
#[test]
fn milling_deep_drilling_cycle() {
    let mut p = params(&[(26, "460"), (27, "1000"), (28, "12."), (29, "300"), (30, "5."), (31, "-50."), (32, "30.")]);
    let block = |p: &mut Parameters, texts: &[&str]| run(p, texts).unwrap();
    let mut moves = Vec::new();
    // N10: "if R31 > R30 then R24=73"; "abs. hodnota prirustku vrtani".
    block(&mut p, &["15313024", "07280028"]);
    assert_eq!((p.get(24), p.get(28)), (Some(78), Some(12_000)));
    // N40: R29 := R30, R25 := R30; R24=1.000.
    block(&mut p, &["00300029", "00300025"]);
    p.set(24, Some(r("1.000")));
    loop {
        // N50/N60: "if R31 >= R29 then R23 je 73" → end.
        block(&mut p, &["16312923"]);
        if p.get(23) == Some(73) {
            break;
        }
        // N70: rapid to R25, then "R29=R29-R28".
        moves.push(("G00", p.get(25).unwrap()));
        block(&mut p, &["02292829"]);
        // N80/N90: R29 > R31 jumps over N100 (R29=R31, last peck retracts to R32).
        block(&mut p, &["15293123"]);
        if p.get(23) != Some(73) {
            block(&mut p, &["00310029", "00320030"]);
        }
        moves.push(("G01", p.get(29).unwrap()));
        moves.push(("G00", p.get(30).unwrap()));
        // N130: "R25=R29+R24 (R24 = 1mm)".
        block(&mut p, &["01292425"]);
    }
    let expected = [
        ("G00", 5_000),
        ("G01", -7_000),
        ("G00", 5_000),
        ("G00", -6_000),
        ("G01", -19_000),
        ("G00", 5_000),
        ("G00", -18_000),
        ("G01", -31_000),
        ("G00", 5_000),
        ("G00", -30_000),
        ("G01", -43_000),
        ("G00", 5_000),
        ("G00", -42_000),
        ("G01", -50_000),
        ("G00", 30_000),
    ];
    assert_eq!(moves, expected);
}

/// Spec 03 §2.3.1, lathe G81 (longitudinal roughing) with example E6: the PROGRAM of N2,
/// the first chip and the finishing length Zt = −70.635.
#[test]
fn lathe_roughing_cycle() {
    let program = [
        "+00280039",
        "+00800085",
        "+31300000",
        "+00020003",
        "+08280028",
        "+22000000",
        "+26010283",
        "+01333333",
        "+01332445",
        "+01453030",
        "+01452811",
        "+01342538",
        "+01383131",
        "+00310044",
        "+00330037",
    ];
    let mut p = params(&[
        (0, "+0"),
        (1, "+1"),
        (2, "+15113010"),
        (3, "+17113010"),
        (24, "-8."),
        (25, "-4."),
        (26, "200"),
        (27, "0.002"),
        (28, "4."),
        (29, "1.678"),
        (30, "-70."),
        (31, "-100."),
    ]);
    for (i, text) in program.iter().enumerate() {
        p.set(7 + i, Some(r(text)));
    }
    // The diameter file reads the radius and doubles it (R33=R33+R33).
    let mut machine = TestMachine { programmed: vec![(1, r("64.")), (2, r("4."))], ..TestMachine::default() };
    let mut block = |p: &mut Parameters, texts: &[&str]| run_with(p, texts, &mut machine, DOUBLE).unwrap();
    block(&mut p, &["+33070021"]);
    let expected = [
        (39, 4_000),   // R39=R28
        (35, -70_000), // R35,R36=R30,R31
        (36, -100_000),
        (3, 15_113_010), // R30 < R00: R03=R02
        (28, -4_000),    // R28=-R28
        (33, 128_000),   // X programmed, doubled
        (34, 4_000),     // Z programmed
        (45, 120_000),   // R45=R33+R24
        (30, 50_000),    // R30=R45+R30
        (11, 116_000),   // R11=R45+R28 (first chip)
        (38, 0),         // R38=R34+R25
        (31, -100_000),  // R31=R38+R31
        (44, -100_000),  // R44=R31
        (37, 128_000),   // R37=R33
    ];
    for (n, value) in expected {
        assert_eq!(p.get(n), Some(value), "R{n}");
    }
    // N50: "R31=R31+R29 Zkraceni" → the first chip ends at Z−98.322.
    block(&mut p, &["+01312931"]);
    assert_eq!(p.get(31), Some(-98_322));
    // N6: R09=R37; the modified instruction R07=R03.
    block(&mut p, &["+00370009", "+00030007"]);
    assert_eq!(p.get(7), Some(15_113_010));
    // N7 G29 runs R05–R08 including the modified R07: "Je-li R11 > R30 pak R10=73".
    let r07 = p.get(7).unwrap().to_string();
    block(&mut p, &["+00110037", "+01112811", &r07, "+00340009"]);
    assert_eq!([p.get(37), p.get(11), p.get(10), p.get(9)], [Some(116_000), Some(112_000), Some(73), Some(4_000)]);
    // N10: R46=0; R27 (2 passes) ≠ 0 → R10=78; R40=abs(R35); R47=R27.
    block(&mut p, &["+02464646", "+19274610", "+07350040", "+00270047"]);
    assert_eq!([p.get(46), p.get(10), p.get(40), p.get(47)], [Some(0), Some(78), Some(70_000), Some(2)]);
    // N11: "R40,41=R29.R40", "R40=R40,41/39", "R09=R44+R40".
    block(&mut p, &["+03294090", "+04903940", "+01444009"]);
    assert_eq!((p.get(40), p.get(9)), (Some(29_365), Some(-70_635)));
    // N15: "R47=R47-R01 dekrement"; "Je-li R47 > R46(0) pak R11=73".
    block(&mut p, &["+00340010", "+02470147", "+15474611"]);
    assert_eq!((p.get(47), p.get(11)), (Some(1), Some(73)));
}

/// Spec 03 §2.3.4, lathe G84 (thread cutting): the first chip from the geometric series,
/// and the Z shift of the alternating infeed.
#[test]
fn lathe_thread_cycle() {
    let program = [
        "+00300044",
        "+23290039",
        "+28283940",
        "+07300039",
        "+04394040",
        "+31300000",
        "+08400040",
        "+22000000",
        "+26010283",
        "+01333333",
        "+00800085",
        "+01332411",
        "+01113030",
        "+01114011",
        "+01342538",
    ];
    let mut p = params(&[(0, "+0"), (24, "1."), (25, "2."), (28, "0.8"), (29, "5"), (30, "-1.5"), (31, "-30.")]);
    for (i, text) in program.iter().enumerate() {
        p.set(6 + i, Some(r(text)));
    }
    let mut machine = TestMachine { programmed: vec![(1, r("10.")), (2, r("0."))], ..TestMachine::default() };
    run_with(&mut p, &["+33060020"], &mut machine, DOUBLE).unwrap();
    // "R39=real(R29)", "R40=soucet geometricke rady", "R39=abs(R30)", "R40=R39/R40 = 1. spona", negated.
    assert_eq!([p.get(44), p.get(39), p.get(40)], [Some(-1_500), Some(1_500), Some(-446)]);
    // "R11=R33+R24", "R30=R11+R30 koncova mira", "R11=R11+R40 (prvni triska)".
    assert_eq!([p.get(30), p.get(11)], [Some(19_500), Some(20_554)]);

    // N55/N56 with pitch 1.5 (R41 = 34 × S = 51.000) and cumulative depth R46 = 0.446.
    let mut p = params(&[(17, "96.000"), (19, "55.426"), (32, "-1"), (41, "51."), (46, "0.446"), (20, "69999.999")]);
    run(&mut p, &["09463242", "03194245", "07450045", "02414543"]).unwrap();
    // "deli trisku 2 (bin. posun)", "(55.426 x T)", "((34 x S) - (55.426 x T))".
    assert_eq!([p.get(42), p.get(45), p.get(43)], [Some(223), Some(12_360), Some(38_640)]);
    // "Je R20 ruzne od 0?" → "((34 x S) - (55.426 x T))/96 do R20": 0.4025 rounds to 0.403.
    run(&mut p, &["21002018", "04431720", "22000000"]).unwrap();
    assert_eq!(p.get(20), Some(403));
}

#[test]
fn messages_are_written_for_programmers() {
    let samples = [
        (ArithError::UndefinedOperation(43), "operation 43 does not exist (the codes are 00–42 and 44–51)"),
        (
            ArithError::UndocumentedOperation(36),
            "operation 36 (inscribed arc) is not described in the manual, so it cannot be evaluated",
        ),
        (field("op1", 97), "the op1 field holds 97, which is not allowed here"),
        (
            ArithError::InProgram { parameter: 7, error: Box::new(ArithError::DivisionByZero) },
            "in the control word held in R07: division by zero",
        ),
        (
            ArithError::IntegerModeNotAllowed(11),
            "operation 11 works only with real values: write the control word with `+` or without a sign",
        ),
    ];
    for (error, text) in samples {
        assert_eq!(error.to_string(), text);
    }
}

/// A small deterministic generator (xorshift), so the test needs no dependency.
struct Random(u64);

impl Random {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    fn value(&mut self) -> Option<Raw> {
        let edges = [0, 1, -1, 73, 1000, -1000, 90_000, MAX_RAW, -MAX_RAW, Raw::MAX, Raw::MIN, 1 << 40];
        match self.below(6) {
            0 => None,
            1 => Some(edges[self.below(edges.len() as u64) as usize]),
            2 => Some(self.below(100_000_000) as Raw * 10 + self.below(100) as Raw),
            3 => Some((self.below(2 * MAX_RAW as u64 + 1) as Raw) - MAX_RAW),
            _ => Some(self.below(2000) as Raw - 1000),
        }
    }
}

/// A machine that answers at random.
struct RandomMachine(std::cell::RefCell<Random>);

impl Machine for RandomMachine {
    fn measured_position(&self, _axis: u8) -> Option<Raw> {
        self.0.borrow_mut().value()
    }
    fn programmed_position(&self, _axis: u8) -> Option<Raw> {
        self.0.borrow_mut().value()
    }
    fn read_table(&self, _table: u8, _row: u16, _column: u16) -> Option<Raw> {
        self.0.borrow_mut().value()
    }
    fn write_table(&mut self, _table: u8, _row: u16, _column: u16, _value: Raw) {}
    fn message(&mut self, _message: Message) {}
}

#[test]
fn no_input_panics() {
    let mut random = Random(0x9E37_79B9_7F4A_7C15);
    let mut machine = RandomMachine(std::cell::RefCell::new(Random(42)));
    let (mut ok, mut failed) = (0, 0);
    for op in 0..100 {
        for _ in 0..300 {
            let mut p = Parameters::unknown();
            for n in 0..PARAMETER_COUNT {
                // Some parameters hold control words, so that op 33 has programs to run.
                let value = if random.below(4) == 0 {
                    Some(random.below(100_000_000) as Raw * if random.below(2) == 0 { 1 } else { -1 })
                } else {
                    random.value()
                };
                p.set(n, value);
            }
            let mut word = || ControlWord {
                integer: random.below(2) == 0,
                op,
                op1: random.below(100) as u8,
                op2: random.below(100) as u8,
                target: random.below(100) as u8,
            };
            let words = [word(), word(), word(), word()];
            let len = 1 + (op as usize + words[0].op1 as usize) % 4;
            let config = ArithConfig { double_precision: random.below(2) == 0 };
            match execute(&words[..len], &mut p, &mut machine, config) {
                Ok(()) => ok += 1,
                Err((index, _)) => {
                    assert!(index < len);
                    failed += 1;
                }
            }
        }
    }
    assert!(ok > 1000 && failed > 1000, "{ok} succeeded, {failed} failed");
}
