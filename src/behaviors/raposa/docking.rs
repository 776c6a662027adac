//! RAPOSA's side of the common `imprint` and `dock_switch` leaves
//! ([`crate::behaviors::common::docking`]): she imprints the pyramid's bands (or a
//! two-block flap's blocks) with her lights and guides as they are, and docked (the
//! pyramid in the socket) she closes the guides.

use super::memory::Memory;
use crate::behaviors::common::docking::DockingMemory;
use crate::perception::RgbView;
use crate::schemas::{Auxiliary, Feedback, Guides};

impl DockingMemory for Memory {
    fn imprint_frame(&mut self, image: &RgbView<'_>) {
        // A frame without the pyramid adds nothing; the finish says whether any did.
        self.source.imprint_frame(image);
    }

    fn finish_imprint(&mut self) -> bool {
        self.imprinted = self.source.finish_imprint(self.now);
        self.imprinted
    }

    fn holding(&self) -> Auxiliary {
        self.aux
    }

    fn docked(&mut self) -> Auxiliary {
        self.aux.set(Guides::Closed);
        self.aux
    }

    fn feedback(&self, phase: &'static str) -> Feedback {
        Memory::feedback(self, phase)
    }
}
