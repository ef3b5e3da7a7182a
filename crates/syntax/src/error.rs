//! Syntax diagnostics: what the parser found wrong with the text, and where.

use std::fmt;

use rowan::TextRange;

use crate::limit::{Omitted, keep_per_line};

/// How serious a finding is. Ordered from least to most severe.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Severity {
    Hint,
    Info,
    Warning,
    Error,
}

impl Severity {
    pub fn as_str(self) -> &'static str {
        match self {
            Severity::Hint => "hint",
            Severity::Info => "info",
            Severity::Warning => "warning",
            Severity::Error => "error",
        }
    }
}

impl fmt::Display for Severity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

macro_rules! syntax_error_kinds {
    ($($variant:ident = $code:literal, $name:literal, $severity:ident, $summary:literal;)*) => {
        /// Every syntax diagnostic. Codes are stable: tools and suppressions
        /// refer to them, so a code is never reused for something else.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
        pub enum SyntaxErrorKind {
            $($variant,)*
        }

        impl SyntaxErrorKind {
            pub const ALL: &'static [SyntaxErrorKind] = &[$(SyntaxErrorKind::$variant,)*];

            /// The stable code, e.g. `S002`.
            pub fn code(self) -> &'static str {
                match self {
                    $(SyntaxErrorKind::$variant => $code,)*
                }
            }

            /// A readable stable name, e.g. `space-in-number`.
            pub fn name(self) -> &'static str {
                match self {
                    $(SyntaxErrorKind::$variant => $name,)*
                }
            }

            pub fn severity(self) -> Severity {
                match self {
                    $(SyntaxErrorKind::$variant => Severity::$severity,)*
                }
            }

            /// One sentence on what the diagnostic reports.
            pub fn summary(self) -> &'static str {
                match self {
                    $(SyntaxErrorKind::$variant => $summary,)*
                }
            }
        }
    };
}

syntax_error_kinds! {
    UnexpectedCharacter = "S001", "unexpected-character", Error, "A character the control does not accept outside comments.";
    SpaceInNumber = "S002", "space-in-number", Error, "A space inside a number.";
    SpaceAfterSign = "S003", "space-after-sign", Error, "A space between a sign and its digits.";
    MissingValue = "S004", "missing-value", Error, "An address letter without a value.";
    NumberWithoutDigits = "S005", "number-without-digits", Error, "A number made of a sign or a point only.";
    NumberWithoutAddress = "S006", "number-without-address", Error, "A number that follows no address letter.";
    SignWithoutAddress = "S007", "sign-without-address", Error, "A sign that follows no address letter.";
    MissingBlockNumber = "S008", "missing-block-number", Error, "Words that belong to no block because no block number N precedes them.";
    LineTooLong = "S009", "line-too-long", Error, "A line longer than the control's 80 characters.";
    TypographicQuote = "S010", "typographic-quote", Warning, "A typographic quote where the control needs a straight double quote.";
    TypographicMinus = "S011", "typographic-minus", Warning, "A typographic minus where the control needs `-`.";
    LowercaseAddress = "S012", "lowercase-address", Warning, "A lowercase address letter.";
    IgnoredPreamble = "S013", "ignored-preamble", Info, "Text before the `%` header, which the control ignores.";
    TextAfterEnd = "S014", "text-after-end", Warning, "Text other than comments after the physical end `*`.";
    MissingProgramNumber = "S015", "missing-program-number", Error, "A program header (CNC8x6 `%`, ISO `O`) without its program number.";
    MisplacedPercent = "S016", "misplaced-percent", Error, "A `%` where the dialect has none: CNC8x6 anywhere but at the start of the program, ISO anywhere but alone on a tape-mark line.";
    ParameterWithoutAssignment = "S017", "parameter-without-assignment", Error, "A parameter `R12` on its own: neither assigned (`R12=5.`) nor used after an address (`XR12`).";
    MissingParameterNumber = "S018", "missing-parameter-number", Error, "`R` without the parameter number.";
    MisplacedEquals = "S019", "misplaced-equals", Error, "An `=` that does not follow a parameter.";
    ByteOrderMark = "S020", "byte-order-mark", Warning, "A file saved as Unicode text with a byte-order mark, which the control does not read.";
    UnclosedComment = "S021", "unclosed-comment", Error, "A comment `(` without its closing `)` on the line.";
    SpaceInWord = "S022", "space-in-word", Warning, "A space between an address and its value or between a sign and its digits, which ISO controls may not accept.";
    DoubledDecimalPoint = "S023", "doubled-decimal-point", Error, "A number with a second decimal point: `7.75.`.";
    ExpectedExpression = "S024", "expected-expression", Error, "A place where an expression (number, variable, bracket or function) must be.";
    UnclosedBracket = "S025", "unclosed-bracket", Error, "A `[` without its closing `]` on the line.";
    MalformedStatement = "S026", "malformed-statement", Error, "A statement (IF, GOTO, WHILE, DO, END, assignment; Sinumerik also DEF, PROC, FOR, CASE, …) missing a required part, or a keyword out of place.";
    TemplatePlaceholder = "S027", "template-placeholder", Error, "A placeholder of a manual's formats (`X..`, `Z...`, `....`) where a value must be written.";
    UnclosedString = "S028", "unclosed-string", Error, "A string `\"` without its closing `\"` on the line.";
    UnclosedParenthesis = "S029", "unclosed-parenthesis", Error, "A `(` without its closing `)` on the line.";
    ParenthesisComment = "S030", "parenthesis-comment", Error, "A Fanuc-style comment `( … )` where Sinumerik reads code: its comments start with `;`.";
}

/// One syntax diagnostic.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct SyntaxError {
    pub kind: SyntaxErrorKind,
    pub range: TextRange,
    pub message: String,
}

impl SyntaxError {
    pub fn new(kind: SyntaxErrorKind, range: TextRange, message: impl Into<String>) -> Self {
        SyntaxError { kind, range, message: message.into() }
    }

    pub fn severity(&self) -> Severity {
        self.kind.severity()
    }
}

/// Errors as the parser collects them: the first ones of each kind on each
/// line, and counts of the others (see `limit`).
#[derive(Debug, Default)]
pub(crate) struct Errors {
    pub(crate) kept: Vec<SyntaxError>,
    pub(crate) omitted: Vec<Omitted<SyntaxErrorKind>>,
}

impl Errors {
    pub(crate) fn append(&mut self, mut other: Errors) {
        self.kept.append(&mut other.kept);
        self.omitted.append(&mut other.omitted);
    }

    /// The errors in canonical order, limited over whole lines, and the
    /// counts of those left out: equal for equal texts however the text was
    /// split into parts.
    pub(crate) fn finish(self, text: &str) -> (Vec<SyntaxError>, Vec<Omitted<SyntaxErrorKind>>) {
        let Errors { mut kept, mut omitted } = self;
        sort_errors(&mut kept);
        let kept = keep_per_line(text, kept, &mut omitted, |e| e.range.start(), |e| e.kind);
        (kept, omitted)
    }
}

/// Puts errors in their canonical order: by position, then kind and text,
/// so that equal inputs give equal lists however they were produced.
pub(crate) fn sort_errors(errors: &mut [SyntaxError]) {
    errors.sort_by(|a, b| {
        (a.range.start(), a.range.end(), a.kind, &a.message).cmp(&(b.range.start(), b.range.end(), b.kind, &b.message))
    });
}

impl fmt::Display for SyntaxError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}[{}] {:?}: {}", self.severity(), self.kind.code(), self.range, self.message)
    }
}
