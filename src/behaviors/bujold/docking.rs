//! Bujold's side of the common `imprint` and `dock_switch` leaves
//! ([`crate::behaviors::common::docking`]): she imprints the flap's two blocks raised, and
//! docked (the pressure plates inside the mother closed, seed 004 §VI.B) she stays
//! lowered.

use super::memory::{Memory, lowered, raised};
use crate::behaviors::common::docking::DockingMemory;
use crate::perception::RgbView;
use crate::schemas::{Auxiliary, Feedback};

impl DockingMemory for Memory {
    fn imprint_frame(&mut self, image: &RgbView<'_>) {
        self.schema.imprint_frame(image);
    }

    fn finish_imprint(&mut self) -> bool {
        self.imprinted = self.schema.finish_imprint(self.now);
        self.imprinted
    }

    fn holding(&self) -> Auxiliary {
        raised()
    }

    fn docked(&mut self) -> Auxiliary {
        lowered()
    }

    fn feedback(&self, phase: &'static str) -> Feedback {
        Memory::feedback(self, phase)
    }
}
