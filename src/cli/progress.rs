//! Progress bars on stderr (indicatif), one per stage.

use std::time::Duration;

use edo_city::build::Progress;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// indicatif bars, one per stage, drawn on stderr only when it is a terminal.
pub struct Bars {
    bar: ProgressBar,
}

impl Bars {
    pub fn new(hidden: bool) -> Bars {
        let bar = ProgressBar::new(0);
        if hidden {
            bar.set_draw_target(ProgressDrawTarget::hidden());
        }
        Bars { bar }
    }
}

impl Progress for Bars {
    fn start(&self, stage: &str, total: u64) {
        self.bar.reset();
        self.bar.set_length(total);
        let style = if total == 0 {
            ProgressStyle::with_template("{spinner} {msg} {elapsed}")
        } else {
            ProgressStyle::with_template("{msg:>14} [{bar:40}] {pos}/{len} {elapsed} eta {eta}")
        };
        if let Ok(s) = style {
            self.bar.set_style(s.progress_chars("=> "));
        }
        self.bar.set_message(stage.to_string());
        if total == 0 {
            self.bar.enable_steady_tick(Duration::from_millis(100));
        }
    }
    fn inc(&self, n: u64) {
        self.bar.inc(n);
    }
    fn finish(&self) {
        self.bar.disable_steady_tick();
        self.bar.finish_and_clear();
    }
}
