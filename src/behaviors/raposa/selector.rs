//! `raposa.seven_state`: the `servo` sequencer's selector (seed 001 §II.D). Each tick
//! the current state is not latched it maps this tick's percept to a state by
//! [`select_state`]; the latched ones (`final`, `region_2`, the back-aways) run until
//! they end.
//!
//! After the region-II manoeuvre (state `look`) it keeps looking until the ellipse is
//! seen, then selects with the angle threshold widened (settling) in that same tick.

use super::memory::Memory;
use super::states::{ServoState, probe_due, select_state};
use crate::arbiter::Selector;
use crate::behaviors::registry::SelectorArgs;
use crate::schemas::Inputs;

/// See the module docs.
pub struct SevenState {
    approach: usize,
    align: usize,
    far_ellipse: usize,
    blue_only: usize,
    search: usize,
    final_: usize,
    leave_dead_zone: usize,
    look: usize,
    probe: Option<usize>,
}

impl SevenState {
    /// The selector of a sequencer with states named `approach`, `align`,
    /// `far_ellipse`, `blue_only`, `search`, `final`, `leave_dead_zone` and `look`, and
    /// optionally `probe` (ours: without it a lone ball in the dead zone is approached,
    /// as in the paper).
    ///
    /// # Errors
    /// A message naming a missing state.
    pub fn new(args: &SelectorArgs<'_>) -> Result<Self, String> {
        Ok(Self {
            approach: args.state("approach")?,
            align: args.state("align")?,
            far_ellipse: args.state("far_ellipse")?,
            blue_only: args.state("blue_only")?,
            search: args.state("search")?,
            final_: args.state("final")?,
            leave_dead_zone: args.state("leave_dead_zone")?,
            look: args.state("look")?,
            probe: args.state("probe").ok(),
        })
    }

    /// The state index of a servo state (`None` for state 7, which `align` hands over to,
    /// and for `probe` in a tree without it).
    pub fn index(&self, state: ServoState) -> Option<usize> {
        Some(match state {
            ServoState::S1Approach => self.approach,
            ServoState::S2Align => self.align,
            ServoState::S3FarEllipse => self.far_ellipse,
            ServoState::S4BlueOnly => self.blue_only,
            ServoState::S5Nothing => self.search,
            ServoState::S6Final => self.final_,
            ServoState::LeaveDeadZone => self.leave_dead_zone,
            ServoState::Probe => return self.probe,
            ServoState::S7Rotate => return None,
        })
    }
}

impl Selector<Memory> for SevenState {
    fn select(&mut self, m: &mut Memory, _inputs: &Inputs<'_>, current: usize) -> Option<usize> {
        let p = m.percept;
        if p.view.is_some() {
            m.search_start = None;
        }
        if current == self.look {
            p.view?;
            m.settling = true;
        }
        let mut state = select_state(&p, &m.gains, m.socket_inset, m.settling);
        if state == ServoState::S1Approach
            && self.probe.is_some()
            && probe_due(&p, &m.gains, m.socket_inset, m.lone, m.probes, m.pair_seen)
        {
            state = ServoState::Probe;
        }
        self.index(state)
    }
}
