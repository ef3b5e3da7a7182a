//! The rules of the run's findings: what the control stops on, and what
//! the run reports without stopping. Codes and names are stable, as the
//! checker's are: `ncc rules` lists them and `ncc.toml` sets their levels.

use ncc_syntax::Severity;

/// What a run's finding is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RunRule {
    ValueRefused,
    BeyondAxisRange,
    ArcOffCircle,
    CompensationFailed,
    ArithmeticFailed,
    ControlWordUnknown,
    CallTargetMissing,
    CallDepth,
    StepBudget,
    MacrocycleWithoutReturn,
    CycleFailed,
    TransformationRefused,
    TransformationIgnored,
    RunsIntoSubprogram,
    DynamicSetOutOfRange,
    MotionWithoutFeed,
    ArcPlaneIncomplete,
    CycleFileMissing,
    ParameterUnknown,
    NotRunYet,
}

impl RunRule {
    pub const ALL: [RunRule; 20] = [
        RunRule::ValueRefused,
        RunRule::BeyondAxisRange,
        RunRule::ArcOffCircle,
        RunRule::CompensationFailed,
        RunRule::ArithmeticFailed,
        RunRule::ControlWordUnknown,
        RunRule::CallTargetMissing,
        RunRule::CallDepth,
        RunRule::StepBudget,
        RunRule::MacrocycleWithoutReturn,
        RunRule::CycleFailed,
        RunRule::TransformationRefused,
        RunRule::TransformationIgnored,
        RunRule::RunsIntoSubprogram,
        RunRule::DynamicSetOutOfRange,
        RunRule::MotionWithoutFeed,
        RunRule::ArcPlaneIncomplete,
        RunRule::CycleFileMissing,
        RunRule::ParameterUnknown,
        RunRule::NotRunYet,
    ];

    /// The code, name, whether the run stops on it, and its summary.
    fn describe(self) -> (&'static str, &'static str, bool, &'static str) {
        match self {
            RunRule::ValueRefused => (
                "E001",
                "value-refused",
                true,
                "A value its address cannot take (sign, digits, range): the control stops on the block.",
            ),
            RunRule::BeyondAxisRange => (
                "E002",
                "beyond-axis-range",
                true,
                "A position outside an axis's range or the machine's travel limits, at a block's end or on an arc's side: the control stops.",
            ),
            RunRule::ArcOffCircle => (
                "E003",
                "arc-off-circle",
                true,
                "An arc whose end point is not on its circle within the machine's tolerance: the control stops.",
            ),
            RunRule::CompensationFailed => (
                "E004",
                "compensation-failed",
                true,
                "Radius compensation cannot build the tool-centre path: the control stops.",
            ),
            RunRule::ArithmeticFailed => (
                "E005",
                "arithmetic-failed",
                true,
                "Parameter arithmetic that cannot be done (a division by zero, an operation out of its domain): the control stops.",
            ),
            RunRule::ControlWordUnknown => (
                "E006",
                "control-word-unknown",
                true,
                "Arithmetic whose control word comes from a value the executor does not know: the run cannot go on.",
            ),
            RunRule::CallTargetMissing => (
                "E007",
                "call-target-missing",
                true,
                "A call or jump to a subprogram, macrocycle file or block that is not there: the control stops.",
            ),
            RunRule::CallDepth => {
                ("E008", "call-depth", true, "Calls nested deeper than the run follows: runaway recursion.")
            }
            RunRule::StepBudget => (
                "E009",
                "step-budget",
                true,
                "The run went past its step budget: a loop that never ends, or runaway calls.",
            ),
            RunRule::MacrocycleWithoutReturn => (
                "E010",
                "macrocycle-without-return",
                true,
                "A called file or program ends without returning to its caller: the control stops.",
            ),
            RunRule::CycleFailed => (
                "E011",
                "cycle-failed",
                true,
                "A fixed cycle that cannot run with the values it is given: the control stops.",
            ),
            RunRule::TransformationRefused => (
                "E012",
                "transformation-refused",
                true,
                "A coordinate recalculation or transformation the control refuses: it stops.",
            ),
            RunRule::TransformationIgnored => (
                "E013",
                "transformation-ignored",
                false,
                "A coordinate recalculation or transformation that does nothing: the run goes on without it.",
            ),
            RunRule::RunsIntoSubprogram => (
                "E014",
                "runs-into-subprogram",
                false,
                "The main body runs into a subprogram without an end of program before it: the run ends there.",
            ),
            RunRule::DynamicSetOutOfRange => (
                "E015",
                "dynamic-set-out-of-range",
                false,
                "A dynamic set the machine does not have: the set in force stays.",
            ),
            RunRule::MotionWithoutFeed => (
                "E016",
                "motion-without-feed",
                false,
                "Motion whose axes cannot move: no feed, or feed per revolution with spindle speed 0.",
            ),
            RunRule::ArcPlaneIncomplete => (
                "E017",
                "arc-plane-incomplete",
                false,
                "An arc without both coordinates of its plane: the run leaves its motion out.",
            ),
            RunRule::CycleFileMissing => (
                "E018",
                "cycle-file-missing",
                false,
                "The machine's cycle file, or a cycle's body in it, is not in the project: the built-in cycle runs instead.",
            ),
            RunRule::ParameterUnknown => (
                "E019",
                "parameter-unknown",
                false,
                "A parameter whose value the executor does not know (a table or register it does not model): words that use it are left out.",
            ),
            RunRule::NotRunYet => {
                ("E020", "not-run-yet", false, "An instruction the executor does not run yet: the time leaves it out.")
            }
        }
    }

    pub fn code(self) -> &'static str {
        self.describe().0
    }

    pub fn name(self) -> &'static str {
        self.describe().1
    }

    /// Whether the run stops on a finding of this rule, as the control
    /// stops on an error.
    pub fn stops(self) -> bool {
        self.describe().2
    }

    pub fn summary(self) -> &'static str {
        self.describe().3
    }

    /// Errors stop the run; what the run leaves out or does not model is
    /// information, the rest a warning.
    pub fn severity(self) -> Severity {
        match self {
            _ if self.stops() => Severity::Error,
            RunRule::ParameterUnknown | RunRule::NotRunYet => Severity::Info,
            _ => Severity::Warning,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::RunRule;

    #[test]
    fn codes_and_names_are_unique_and_in_order() {
        for (index, rule) in RunRule::ALL.iter().enumerate() {
            assert_eq!(*rule as usize, index, "ALL is in declaration order");
            assert_eq!(rule.code(), format!("E{:03}", index + 1));
            assert!(RunRule::ALL[..index].iter().all(|other| other.name() != rule.name()), "{rule:?}");
        }
    }
}
