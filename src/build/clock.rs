//! The wall and processor time of a build's stages, for `--timings`: a stage over a second
//! that keeps one of two cores idle shows as a CPU/wall ratio under 2.

use std::time::{Duration, Instant};

use cpu_time::ProcessTime;

/// One stage's times.
#[derive(Debug, Clone, PartialEq)]
pub struct StageTime {
    /// What the stage does, as `--timings` prints it.
    pub name: &'static str,
    /// Its wall time.
    pub wall: Duration,
    /// The processor time of the whole process over it, all threads summed (zero where the
    /// system does not say).
    pub cpu: Duration,
}

impl StageTime {
    /// Processor time over wall time: 2.0 is both of two cores busy throughout.
    pub fn busy(&self) -> f64 {
        self.cpu.as_secs_f64() / self.wall.as_secs_f64().max(1e-9)
    }
}

/// A stage's clocks, started.
#[derive(Debug, Clone, Copy)]
pub struct StageClock {
    wall: Instant,
    cpu: Option<ProcessTime>,
}

impl StageClock {
    /// Starts both clocks.
    pub fn start() -> Self {
        StageClock {
            wall: Instant::now(),
            cpu: ProcessTime::try_now().ok(),
        }
    }

    /// The stage's times since [`StageClock::start`].
    pub fn stop(self, name: &'static str) -> StageTime {
        let cpu = (self.cpu)
            .and_then(|c| c.try_elapsed().ok())
            .unwrap_or_default();
        StageTime {
            name,
            wall: self.wall.elapsed(),
            cpu,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn busy_is_processor_time_over_wall_time() {
        let s = StageTime {
            name: "tiles",
            wall: Duration::from_millis(1000),
            cpu: Duration::from_millis(1800),
        };
        assert!((s.busy() - 1.8).abs() < 1e-12);
        let zero = StageTime {
            wall: Duration::ZERO,
            ..s
        };
        assert!(zero.busy().is_finite());
    }

    #[test]
    fn a_stage_that_works_has_processor_time() {
        let clock = StageClock::start();
        let mut x = 0u64;
        for i in 0..20_000_000u64 {
            x = x.wrapping_mul(31).wrapping_add(i);
        }
        std::hint::black_box(x);
        let s = clock.stop("work");
        assert!(s.cpu > Duration::ZERO && s.wall > Duration::ZERO);
    }
}
