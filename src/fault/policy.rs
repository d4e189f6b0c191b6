//! How the integrator asks about faults at no cost when there are none ([`NoFaults`]).

use super::*;

/// What the integrator asks while rendering: is this fault in force, and with which value?
/// Implemented by [`NoFaults`], whose every answer is the constant `false` (so that a render
/// without faults compiles to the code without any check), and by [`FaultSet`].
pub trait FaultPolicy: Copy + Send + Sync {
    fn has(&self, fault: Fault) -> bool;
    /// The values of the families; only read after [`FaultPolicy::has`] said yes.
    fn set(&self) -> FaultSet;
}

/// No fault: every check is `false` at compile time.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoFaults;

impl FaultPolicy for NoFaults {
    #[inline(always)]
    fn has(&self, _: Fault) -> bool {
        false
    }

    #[inline(always)]
    fn set(&self) -> FaultSet {
        FaultSet::NONE
    }
}

impl FaultPolicy for FaultSet {
    #[inline(always)]
    fn has(&self, fault: Fault) -> bool {
        self.contains(fault)
    }

    #[inline(always)]
    fn set(&self) -> FaultSet {
        *self
    }
}
