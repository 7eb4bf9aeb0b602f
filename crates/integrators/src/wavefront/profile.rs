//! Where a wavefront render's time goes: wall time per stage and how full the batches were,
//! summed over threads, for `render --stats`.

use std::time::{Duration, Instant};

/// The stages of one round of a batch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Stage {
    /// Refilling finished lanes with camera rays.
    Generate,
    /// Closest-hit stream.
    Trace,
    /// The vertex's random numbers, all lanes at once.
    Draw,
    /// Emission, light sampling, BSDF sampling, roulette (lane by lane).
    Shade,
    /// The plain Lambertian vertices' BSDF, eight lanes at a time, and their finish.
    Bsdf,
    /// Shadow-ray stream and its contributions.
    Shadow,
    /// Finished paths into the film, compaction.
    Accumulate,
}

impl Stage {
    pub const ALL: [Stage; 7] = [
        Stage::Generate,
        Stage::Trace,
        Stage::Draw,
        Stage::Shade,
        Stage::Bsdf,
        Stage::Shadow,
        Stage::Accumulate,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Stage::Generate => "camera rays",
            Stage::Trace => "trace",
            Stage::Draw => "sample draws",
            Stage::Shade => "shade",
            Stage::Bsdf => "lambert bsdf",
            Stage::Shadow => "shadow rays",
            Stage::Accumulate => "accumulate",
        }
    }
}

/// Per-stage time (summed over threads) and batch occupancy.
#[derive(Clone, Debug, Default)]
pub(crate) struct Profile {
    pub time: [Duration; 7],
    /// Rounds run, lanes busy over all rounds, lane slots over all rounds.
    pub rounds: u64,
    pub busy: u64,
    pub slots: u64,
}

impl Profile {
    /// Charges the time since `clock` to `stage` and restarts the clock.
    #[inline]
    pub fn lap(&mut self, stage: Stage, clock: &mut Instant) {
        let now = Instant::now();
        self.time[stage as usize] += now - *clock;
        *clock = now;
    }

    /// Records a round with `busy` of `capacity` lanes in use.
    #[inline]
    pub fn round(&mut self, busy: usize, capacity: usize) {
        self.rounds += 1;
        self.busy += busy as u64;
        self.slots += capacity as u64;
    }

    /// Adds `other` into this one and clears it.
    pub fn take(&mut self, other: &mut Profile) {
        for (a, b) in self.time.iter_mut().zip(&other.time) {
            *a += *b;
        }
        self.rounds += other.rounds;
        self.busy += other.busy;
        self.slots += other.slots;
        *other = Profile::default();
    }

    /// Mean share of lanes busy per round.
    pub fn occupancy(&self) -> f64 {
        self.busy as f64 / self.slots.max(1) as f64
    }

    /// `stage 41 %, ...` over the total stage time.
    pub fn shares(&self) -> String {
        let total: Duration = self.time.iter().sum();
        let total = total.as_secs_f64().max(1e-12);
        Stage::ALL
            .iter()
            .map(|s| {
                let t = self.time[*s as usize].as_secs_f64();
                format!("{} {:.0} %", s.name(), 100.0 * t / total)
            })
            .collect::<Vec<_>>()
            .join(", ")
    }
}
