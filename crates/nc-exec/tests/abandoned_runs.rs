//! A run whose environment says it is abandoned ends at its next look, in
//! every control's interpreter: the editor gives up a run its next key
//! would throw away.

use std::cell::Cell;

use nc_exec::{
    machine::MachineConfig,
    run::{ABANDON_INTERVAL, Called, Environment, run},
};
use ncc_catalog::Dialect;

/// No files; abandoned from its `after`th look on, counting the looks.
struct GivenUp {
    after: usize,
    looks: Cell<usize>,
}

impl Environment for GivenUp {
    fn file(&self, _called: &Called) -> Option<String> {
        None
    }

    fn abandoned(&self) -> bool {
        self.looks.set(self.looks.get() + 1);
        self.looks.get() > self.after
    }
}

/// `blocks` straight moves and the program's end, in `control`'s language.
fn program(control: Dialect, blocks: usize) -> String {
    let moves = (0..blocks).map(|i| format!("G1 X{} F1000\n", i % 100));
    match control {
        Dialect::Cnc8x6 => {
            let numbered = moves.enumerate().map(|(i, m)| format!("N{} {m}", i + 1));
            format!("%1\n{}N{} M30\n", numbered.collect::<String>(), blocks + 1)
        }
        Dialect::HaasLathe => format!("%\nO1000\n{}M30\n%\n", moves.map(|m| m.replace('X', "Z-")).collect::<String>()),
        Dialect::Sinumerik => format!("{}M30\n", moves.collect::<String>()),
    }
}

#[test]
fn an_abandoned_run_ends_at_its_next_look() {
    let blocks = 10 * ABANDON_INTERVAL;
    for control in [Dialect::Cnc8x6, Dialect::HaasLathe, Dialect::Sinumerik] {
        let machine = MachineConfig::of_control(control);
        let text = program(control, blocks);
        let whole = run(&text, &GivenUp { after: usize::MAX, looks: Cell::new(0) }, &machine, usize::MAX);
        assert!(whole.blocks_run > blocks, "{control:?}: {} blocks run", whole.blocks_run);
        let given_up = GivenUp { after: 2, looks: Cell::new(0) };
        let cut = run(&text, &given_up, &machine, usize::MAX);
        // The first look that finds it abandoned ends the run; Sinumerik's
        // ends its reading of the program, and the run looks once more.
        assert!((3..=4).contains(&given_up.looks.get()), "{control:?}: {} looks", given_up.looks.get());
        assert!(cut.blocks_run <= 3 * ABANDON_INTERVAL, "{control:?}: {} blocks run", cut.blocks_run);
    }
}
