//! Syntax diagnostics: what the parser found wrong with the text, and where.

use std::fmt;

use rowan::TextRange;

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
    ($($variant:ident = $code:literal, $name:literal, $severity:ident;)*) => {
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
        }
    };
}

syntax_error_kinds! {
    UnexpectedCharacter = "S001", "unexpected-character", Error;
    SpaceInNumber = "S002", "space-in-number", Error;
    SpaceAfterSign = "S003", "space-after-sign", Error;
    MissingValue = "S004", "missing-value", Error;
    NumberWithoutDigits = "S005", "number-without-digits", Error;
    NumberWithoutAddress = "S006", "number-without-address", Error;
    SignWithoutAddress = "S007", "sign-without-address", Error;
    MissingBlockNumber = "S008", "missing-block-number", Error;
    LineTooLong = "S009", "line-too-long", Error;
    TypographicQuote = "S010", "typographic-quote", Warning;
    TypographicMinus = "S011", "typographic-minus", Warning;
    LowercaseAddress = "S012", "lowercase-address", Warning;
    IgnoredPreamble = "S013", "ignored-preamble", Info;
    TextAfterEnd = "S014", "text-after-end", Warning;
    MissingProgramNumber = "S015", "missing-program-number", Error;
    MisplacedPercent = "S016", "misplaced-percent", Error;
    ParameterWithoutAssignment = "S017", "parameter-without-assignment", Error;
    MissingParameterNumber = "S018", "missing-parameter-number", Error;
    MisplacedEquals = "S019", "misplaced-equals", Error;
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
