//! Where a run's samples go: the [`SampleSink`] every propagator records into, in time order
//! (`docs/model.md` section 3a, sample times).

use super::Observation;
use crate::model::StateVector;

/// Receives the simulated samples of a run, in time order.
pub trait SampleSink {
    /// Sample `index` (of the requested times) is `obs`, observed from the state `x` (for a
    /// time before release, the carriage state).
    fn record(&mut self, index: usize, obs: &Observation, x: &StateVector);
}

/// A sink behind a pointer: the propagators are compiled once, for `&mut dyn SampleSink`.
impl<T: SampleSink + ?Sized> SampleSink for &mut T {
    fn record(&mut self, index: usize, obs: &Observation, x: &StateVector) {
        (**self).record(index, obs, x);
    }
}

impl SampleSink for Vec<Observation> {
    fn record(&mut self, _index: usize, obs: &Observation, _x: &StateVector) {
        self.push(*obs);
    }
}

impl SampleSink for Vec<(Observation, StateVector)> {
    fn record(&mut self, _index: usize, obs: &Observation, x: &StateVector) {
        self.push((*obs, *x));
    }
}
