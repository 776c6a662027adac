//! The campaign runner: a loaded campaign's runs shared out to worker threads, each with
//! its own buffers, and the records gathered back in run order. Runs are seeded by their
//! index alone, so the records do not depend on how many workers there are.

use super::run::{Context, Workspace};
use super::{LoadedCampaign, PoseRun, runs};
use crate::sim::SimError;
use std::path::Path;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Runs every run of a loaded campaign on `jobs` threads (0: one per core) and returns
/// the records in run order; `each` sees each record as it finishes, in any order. With
/// `frames`, each run's measured frames are saved there as `RUN-CAMERA.png`.
///
/// # Errors
/// [`SimError`] when the profile's model or cameras cannot be built, or a frame cannot
/// be searched.
pub fn run_campaign(
    loaded: &LoadedCampaign,
    jobs: usize,
    frames: Option<&Path>,
    each: &(dyn Fn(&PoseRun) + Sync),
) -> Result<Vec<PoseRun>, SimError> {
    let ctx = Context::new(loaded, frames)?;
    let specs = runs(&loaded.campaign);
    let jobs = if jobs == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        jobs
    };
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<Result<PoseRun, SimError>>>> = Mutex::new((0..specs.len()).map(|_| None).collect());
    std::thread::scope(|s| {
        for _ in 0..jobs.min(specs.len()).max(1) {
            s.spawn(|| {
                let mut ws = Workspace::new(&loaded.profile);
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(spec) = specs.get(i) else { break };
                    let r = ctx.run(spec, &mut ws);
                    if let Ok(rec) = &r {
                        each(rec);
                    }
                    if let Ok(mut all) = results.lock() {
                        all[i] = Some(r);
                    }
                }
            });
        }
    });
    results
        .into_inner()
        .map_err(poisoned)?
        .into_iter()
        .map(|r| r.unwrap_or_else(|| Err(SimError::Unsupported("a run did not finish".into()))))
        .collect()
}

/// The error a worker's panic (a poisoned lock) becomes.
fn poisoned<T>(_: T) -> SimError {
    SimError::Unsupported("a worker panicked".into())
}
