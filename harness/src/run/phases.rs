//! Where a run's time goes: wall-clock and process CPU seconds per phase (building test beds and
//! references, running cells, analysis, writing files and plots), printed by the command line
//! after each experiment. Phases nest: a phase entered inside another (the cells an experiment's
//! analysis runs, the plans it builds) is charged to the inner one only, so the phases of an
//! experiment add up to its time. Only the thread that called [`track`] records (the command
//! line's main thread; the work it waits on in a thread pool is in the process CPU time); anywhere
//! else [`enter`] is a no-op, so library users and tests pay nothing.

use std::cell::RefCell;
use std::time::Instant;

/// A phase of a run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// Building plans: test beds with their references, estimators.
    Build,
    /// Running (or reading back) cells.
    Cells,
    /// Claims and the experiment's own analysis (beyond what it builds and runs).
    Analysis,
    /// Result files, plots and the report.
    Output,
}

impl Phase {
    /// Every phase, in the order they are printed.
    pub const ALL: [Phase; 4] = [Phase::Build, Phase::Cells, Phase::Analysis, Phase::Output];

    /// Its name in the printed line.
    pub fn name(self) -> &'static str {
        match self {
            Phase::Build => "build",
            Phase::Cells => "cells",
            Phase::Analysis => "analysis",
            Phase::Output => "output",
        }
    }

    fn index(self) -> usize {
        self as usize
    }
}

/// Wall-clock and process CPU seconds per phase ([`Phase::ALL`] order).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Times {
    /// Wall-clock seconds per phase.
    pub wall: [f64; 4],
    /// Process CPU seconds (user + system, every thread) per phase.
    pub cpu: [f64; 4],
}

impl Times {
    /// The sum over phases: (wall, CPU).
    pub fn total(&self) -> (f64, f64) {
        (self.wall.iter().sum(), self.cpu.iter().sum())
    }

    /// Adds `other` phase by phase.
    pub fn add(&mut self, other: &Times) {
        for i in 0..4 {
            self.wall[i] += other.wall[i];
            self.cpu[i] += other.cpu[i];
        }
    }

    /// One line: `build 1.2 s (CPU 1.3 s), cells ...`.
    pub fn line(&self) -> String {
        let (w, c) = self.total();
        let parts: Vec<String> = Phase::ALL
            .iter()
            .map(|p| format!("{} {:.1} s (CPU {:.1} s)", p.name(), self.wall[p.index()], self.cpu[p.index()]))
            .collect();
        format!("{}; total {w:.1} s (CPU {c:.1} s)", parts.join(", "))
    }
}

/// A markdown table of experiments' phase times (wall and CPU seconds), with a total row.
pub fn table(names: &[&str], times: &[Times]) -> String {
    let mut header = vec!["experiment".to_string()];
    for p in Phase::ALL {
        header.push(format!("{} wall", p.name()));
        header.push(format!("{} CPU", p.name()));
    }
    header.extend(["wall".to_string(), "CPU".to_string()]);
    let row = |name: &str, t: &Times| {
        let mut r = vec![name.to_string()];
        for i in 0..4 {
            r.push(format!("{:.1}", t.wall[i]));
            r.push(format!("{:.1}", t.cpu[i]));
        }
        let (w, c) = t.total();
        r.extend([format!("{w:.1}"), format!("{c:.1}")]);
        r
    };
    let mut rows: Vec<Vec<String>> = names.iter().zip(times).map(|(n, t)| row(n, t)).collect();
    let mut all = Times::default();
    times.iter().for_each(|t| all.add(t));
    rows.push(row("total", &all));
    let header: Vec<&str> = header.iter().map(String::as_str).collect();
    format!(
        "\nseconds per phase (process CPU: every thread, user + system)\n{}\n",
        crate::output::report::markdown_table(&header, &rows)
    )
}

struct Tracker {
    times: Times,
    /// The open phases, innermost last, each with when it was last charged (wall, CPU).
    stack: Vec<(Phase, Instant, f64)>,
}

thread_local! {
    static TRACKER: RefCell<Option<Tracker>> = const { RefCell::new(None) };
}

/// Seconds of CPU the whole process has used (`CLOCK_PROCESS_CPUTIME_ID`); 0 where the clock is
/// unavailable.
pub fn process_seconds() -> f64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `ts` is a valid, writable timespec; clock_gettime only writes it.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut ts) };
    if rc != 0 {
        return 0.0;
    }
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

/// Starts recording on the calling thread (from zero).
pub fn track() {
    TRACKER.with(|t| *t.borrow_mut() = Some(Tracker { times: Times::default(), stack: Vec::new() }));
}

/// The times recorded on this thread since [`track`] or the last `take`, reset to zero (phases
/// still open keep running from now).
pub fn take() -> Times {
    TRACKER.with(|t| {
        let mut t = t.borrow_mut();
        let Some(tr) = t.as_mut() else { return Times::default() };
        charge(tr);
        std::mem::take(&mut tr.times)
    })
}

/// Charges the time since the innermost open phase was last charged to it.
fn charge(tr: &mut Tracker) {
    let (now, cpu) = (Instant::now(), process_seconds());
    if let Some((phase, since, cpu0)) = tr.stack.last_mut() {
        tr.times.wall[phase.index()] += now.duration_since(*since).as_secs_f64();
        tr.times.cpu[phase.index()] += (cpu - *cpu0).max(0.0);
        *since = now;
        *cpu0 = cpu;
    }
}

/// An open phase; it ends when dropped.
#[must_use = "the phase ends when this is dropped"]
pub struct Guard {
    recording: bool,
}

/// Enters `phase` until the guard is dropped (a no-op on a thread that is not recording).
pub fn enter(phase: Phase) -> Guard {
    let recording = TRACKER.with(|t| {
        let mut t = t.borrow_mut();
        let Some(tr) = t.as_mut() else { return false };
        charge(tr);
        tr.stack.push((phase, Instant::now(), process_seconds()));
        true
    });
    Guard { recording }
}

impl Drop for Guard {
    fn drop(&mut self) {
        if !self.recording {
            return;
        }
        TRACKER.with(|t| {
            let mut t = t.borrow_mut();
            if let Some(tr) = t.as_mut() {
                charge(tr);
                tr.stack.pop();
                if let Some((_, since, cpu0)) = tr.stack.last_mut() {
                    *since = Instant::now();
                    *cpu0 = process_seconds();
                }
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spin(seconds: f64) {
        let t0 = Instant::now();
        let mut x = 0u64;
        while t0.elapsed().as_secs_f64() < seconds {
            x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
        }
    }

    #[test]
    fn nested_phases_are_charged_to_the_innermost_and_add_up() {
        track();
        let t0 = Instant::now();
        {
            let _a = enter(Phase::Analysis);
            spin(0.02);
            {
                let _c = enter(Phase::Cells);
                spin(0.03);
            }
            spin(0.01);
        }
        let outside = t0.elapsed().as_secs_f64();
        let t = take();
        assert!(t.wall[Phase::Cells.index()] >= 0.03, "{t:?}");
        assert!(t.wall[Phase::Analysis.index()] >= 0.03, "{t:?}");
        assert!(t.total().0 <= outside + 1e-6, "the inner phase is not charged twice: {t:?} in {outside} s");
        assert_eq!(t.wall[Phase::Build.index()], 0.0);
        assert!(t.cpu[Phase::Cells.index()] > 0.0);
        assert_eq!(take().total(), (0.0, 0.0), "take resets");
        assert!(t.line().contains("cells"));
        let md = table(&["a"], &[t]);
        assert!(md.contains("| total") && md.contains("cells CPU"), "{md}");
    }

    #[test]
    fn a_thread_that_does_not_track_records_nothing() {
        std::thread::spawn(|| {
            let _g = enter(Phase::Build);
            spin(0.005);
            drop(_g);
            assert_eq!(take(), Times::default());
        })
        .join()
        .unwrap();
    }
}
