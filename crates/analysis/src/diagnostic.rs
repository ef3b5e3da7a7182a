//! What the analysis reports: diagnostics with ranges, related locations and
//! quick fixes, and the registry of rules with their stable codes.

use nc_exec::run::RunRule;
use ncc_syntax::{Severity, SyntaxError, SyntaxErrorKind, TextEdit, TextRange};

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
    /// The text it points at has no effect (editors fade it).
    pub unnecessary: bool,
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
    pub fn new(rule: &'static Rule, range: TextRange, message: impl Into<String>) -> Diagnostic {
        Diagnostic {
            range,
            severity: rule.severity,
            code: rule.code,
            name: rule.name,
            message: message.into(),
            related: Vec::new(),
            fixes: Vec::new(),
            unnecessary: rule.unnecessary,
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
            unnecessary: syntax_unnecessary(error.kind),
        }
    }

    /// The diagnostic where it stands after `edit` (made after it was
    /// computed), or `None` when the edit touches what it points at. Lets
    /// an editor keep slow findings in place until they are recomputed.
    pub fn moved_through(mut self, edit: &TextEdit) -> Option<Diagnostic> {
        let map = |range: TextRange| -> Option<TextRange> {
            let deleted = edit.delete;
            if range.end() <= deleted.start() {
                Some(range)
            } else if range.start() >= deleted.end() {
                let inserted = ncc_syntax::TextSize::of(edit.insert.as_str());
                Some(TextRange::new(range.start() - deleted.len() + inserted, range.end() - deleted.len() + inserted))
            } else {
                None
            }
        };
        self.range = map(self.range)?;
        for related in self.related.iter_mut().filter(|r| r.file.is_none()) {
            related.range = map(related.range)?;
        }
        for fix in &mut self.fixes {
            for fix_edit in &mut fix.edits {
                fix_edit.delete = map(fix_edit.delete)?;
            }
        }
        Some(self)
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

/// Text the control ignores.
fn syntax_unnecessary(kind: SyntaxErrorKind) -> bool {
    matches!(kind, SyntaxErrorKind::IgnoredPreamble | SyntaxErrorKind::TextAfterEnd)
}

/// The parser's diagnostics as rules, so that configuration, suppression
/// and listings treat them like every other rule.
static SYNTAX_RULES: std::sync::LazyLock<Vec<Rule>> = std::sync::LazyLock::new(|| {
    SyntaxErrorKind::ALL
        .iter()
        .map(|kind| Rule {
            code: kind.code(),
            name: kind.name(),
            severity: kind.severity(),
            summary: kind.summary(),
            opt_in: false,
            unnecessary: syntax_unnecessary(*kind),
        })
        .collect()
});

/// The executor's findings as rules: `ncc run` reports them, and
/// configuration and listings treat them like every other rule.
static RUN_RULES: std::sync::LazyLock<Vec<Rule>> = std::sync::LazyLock::new(|| {
    RunRule::ALL
        .iter()
        .map(|rule| Rule {
            code: rule.code(),
            name: rule.name(),
            severity: rule.severity(),
            summary: rule.summary(),
            opt_in: false,
            unnecessary: false,
        })
        .collect()
});

/// A rule: what a diagnostic is about. Codes and names are stable:
/// configuration and suppression comments refer to them.
#[derive(Debug, PartialEq, Eq, Hash)]
pub struct Rule {
    pub code: &'static str,
    pub name: &'static str,
    /// The severity unless the project configuration changes it.
    pub severity: Severity,
    /// One line on what the rule checks.
    pub summary: &'static str,
    /// Off unless the project configuration gives it a level (a matter of
    /// style that not every shop follows).
    pub opt_in: bool,
    /// Its findings point at text that has no effect.
    pub unnecessary: bool,
}

impl Rule {
    /// The rule of an executor's finding.
    pub fn of_run(rule: RunRule) -> &'static Rule {
        // `RunRule::ALL` lists the rules in their declaration order.
        &RUN_RULES[rule as usize]
    }
}

/// The parser's rules (`Rule::all` lists them with the dialects').
pub(crate) fn syntax_rules() -> impl Iterator<Item = &'static Rule> {
    SYNTAX_RULES.iter()
}

/// The executor's rules.
pub(crate) fn run_rules() -> impl Iterator<Item = &'static Rule> {
    RUN_RULES.iter()
}

/// Declares a check module's rules as statics and lists them in `RULES`.
/// A trailing `, opt_in` marks a rule that is off unless configured, a
/// trailing `, unnecessary` one whose findings point at text without effect.
macro_rules! declare_rules {
    (@opt_in opt_in) => { true };
    (@opt_in $($other:ident)?) => { false };
    (@unnecessary unnecessary) => { true };
    (@unnecessary $($other:ident)?) => { false };
    ($($ident:ident = $code:literal, $name:literal, $severity:ident, $summary:literal $(, $marker:ident)?;)*) => {
        $(
            pub(crate) static $ident: $crate::Rule = $crate::Rule {
                code: $code,
                name: $name,
                severity: ncc_syntax::Severity::$severity,
                summary: $summary,
                opt_in: $crate::diagnostic::declare_rules!(@opt_in $($marker)?),
                unnecessary: $crate::diagnostic::declare_rules!(@unnecessary $($marker)?),
            };
        )*
        pub(crate) static RULES: &[&$crate::Rule] = &[$(&$ident,)*];
    };
}
pub(crate) use declare_rules;
