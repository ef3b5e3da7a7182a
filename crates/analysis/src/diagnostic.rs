//! What the analysis reports: diagnostics with ranges, related locations and
//! quick fixes, and the registry of rules with their stable codes.

use ncc_syntax::{Severity, SyntaxError, TextEdit, TextRange};

/// A finding in one file.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Diagnostic {
    pub range: TextRange,
    pub severity: Severity,
    /// Stable identifier, e.g. `P101` or `S002`.
    pub code: &'static str,
    /// Stable readable name, e.g. `missing-g70`.
    pub name: &'static str,
    pub message: String,
    /// Other places that explain the finding (where a value was assigned,
    /// where a subprogram starts).
    pub related: Vec<Related>,
    /// Edits that would resolve it.
    pub fixes: Vec<Fix>,
}

/// A place related to a diagnostic.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Related {
    /// The file, when it is not the diagnostic's own (a macrocycle file).
    pub file: Option<String>,
    pub range: TextRange,
    pub message: String,
}

/// A quick fix: edits of the diagnostic's file.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Fix {
    pub title: String,
    pub edits: Vec<TextEdit>,
}

impl Diagnostic {
    pub fn new(rule: Rule, range: TextRange, message: impl Into<String>) -> Diagnostic {
        Diagnostic {
            range,
            severity: rule.severity(),
            code: rule.code(),
            name: rule.name(),
            message: message.into(),
            related: Vec::new(),
            fixes: Vec::new(),
        }
    }

    pub fn with_related(mut self, file: Option<String>, range: TextRange, message: impl Into<String>) -> Self {
        self.related.push(Related { file, range, message: message.into() });
        self
    }

    pub fn with_fix(mut self, title: impl Into<String>, edits: Vec<TextEdit>) -> Self {
        self.fixes.push(Fix { title: title.into(), edits });
        self
    }

    pub(crate) fn from_syntax(error: &SyntaxError) -> Diagnostic {
        Diagnostic {
            range: error.range,
            severity: error.severity(),
            code: error.kind.code(),
            name: error.kind.name(),
            message: error.message.clone(),
            related: Vec::new(),
            fixes: Vec::new(),
        }
    }

    /// The diagnostic moved by `offset` (block-relative ranges become file ranges).
    pub(crate) fn shifted(mut self, offset: ncc_syntax::TextSize) -> Self {
        self.range += offset;
        for related in self.related.iter_mut().filter(|r| r.file.is_none()) {
            related.range += offset;
        }
        for fix in &mut self.fixes {
            for edit in &mut fix.edits {
                edit.delete += offset;
            }
        }
        self
    }
}

macro_rules! rules {
    ($($variant:ident = $code:literal, $name:literal, $severity:ident, $summary:literal;)*) => {
        /// Every semantic rule. Codes and names are stable: configuration
        /// and suppression comments refer to them.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
        pub enum Rule {
            $($variant,)*
        }

        impl Rule {
            pub const ALL: &'static [Rule] = &[$(Rule::$variant,)*];

            pub fn code(self) -> &'static str {
                match self {
                    $(Rule::$variant => $code,)*
                }
            }

            pub fn name(self) -> &'static str {
                match self {
                    $(Rule::$variant => $name,)*
                }
            }

            /// The severity unless the project configuration changes it.
            pub fn severity(self) -> Severity {
                match self {
                    $(Rule::$variant => Severity::$severity,)*
                }
            }

            /// One line on what the rule checks.
            pub fn summary(self) -> &'static str {
                match self {
                    $(Rule::$variant => $summary,)*
                }
            }
        }
    };
}

rules! {
    // Block rules: one block and the catalogue.
    UnknownCode = "B201", "unknown-code", Error, "A G code the control does not know.";
    UnknownAddress = "B202", "unknown-address", Error, "A letter that is no address of the dialect or the configured axes.";
    AddressRepeated = "B203", "address-repeated", Error, "An address written twice in one block.";
    GroupConflict = "B204", "group-conflict", Error, "Two codes of one G or M group in one block.";
    TooManyDigits = "B205", "too-many-digits", Error, "A value with more digits than its address's format allows.";
    ValueOutOfRange = "B206", "value-out-of-range", Error, "A value outside its address's range.";
    UnexpectedSign = "B207", "unexpected-sign", Error, "A sign on an address that takes only unsigned values.";
    UnexpectedDecimalPoint = "B208", "unexpected-decimal-point", Warning, "A decimal point on a code, count or number.";
    MissingRequiredAddress = "B209", "missing-required-address", Error, "A function without the address it needs in its block.";
    NotSubstitutable = "B210", "not-substitutable", Error, "A parameter used where the control does not substitute one.";
    TooManyAxes = "B211", "too-many-axes", Error, "More than six coordinates in one block.";
    LengthCompensationDigits = "B212", "length-compensation-digits", Error, "An `&` digit other than 0, 1 or 2.";
    DecimalPointRequired = "B213", "decimal-point-required", Error, "E written without its mandatory decimal point.";
    SkipDigitIgnored = "B214", "skip-digit-ignored", Warning, "A digit after `/`, which the control does not evaluate.";
    SkipRepeated = "B215", "skip-repeated", Warning, "More than one `/` in a block.";
    MeaninglessAddress = "B216", "meaningless-address", Warning, "L or Q in a block without a function that reads it.";
    TooManyParameterAssignments = "B217", "too-many-parameter-assignments", Error, "More than 95 parameter assignments in one block.";
    G98NotAlone = "B218", "g98-not-alone", Error, "G98 (end of helix) shares its block with other words.";
    DwellOverridesRepeat = "B219", "dwell-overrides-repeat", Warning, "G04 with a call or jump: Q is the dwell and the call runs once.";
    SwallowedWords = "B221", "swallowed-words", Warning, "An unclosed comment that hides words after it.";
    OffsetTableForm = "B223", "offset-table-form", Warning, "G92/G93 without the group-5 code that names the table row.";
}
