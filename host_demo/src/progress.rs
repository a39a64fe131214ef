//! Progress of long runs on stderr (DESIGN.md §8): a bar on a terminal; elsewhere (a pipe, a CI log,
//! `nohup`) plain lines, so that a run never looks hung.
//!
//! A run counts its steps (models, configurations, lights): [`progress`]. Within a step, the code doing
//! the work opens phases with [`phase`] — the GPU frames, the CPU reference's rows, the RT peer's frames —
//! each with its count and the time it has left. A phase reports to the innermost [`Progress`] alive on
//! the calling thread (it is a no-op without one), so the helpers the tests share take no progress
//! argument. Phases nest ("RT peer: frames 3/30").
//!
//! Off a terminal a line is printed when a step or a phase starts, and the run's state again whenever
//! [`interval`] passes without a line (10 s unless [`INTERVAL_ENV`] says otherwise), whatever the work (a
//! single long GPU frame, a driver's pipeline build): "bench [1/3] 02_stanford_bunny_69k.obj: CPU
//! reference 412/1080, about 52 s left (95 s elapsed)".

use std::cell::RefCell;
use std::marker::PhantomData;
use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Environment variable: the longest silence, in seconds, between progress lines off a terminal (default
/// 10).
pub const INTERVAL_ENV: &str = "HRTS_PROGRESS_SECONDS";

/// The longest silence between progress lines off a terminal: [`INTERVAL_ENV`] if it holds a positive
/// number of seconds, else 10 s.
pub fn interval() -> Duration {
    std::env::var(INTERVAL_ENV)
        .ok()
        .and_then(|s| s.trim().parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s > 0.0)
        .map_or(Duration::from_secs(10), Duration::from_secs_f64)
}

thread_local! {
    /// The runs alive on this thread, innermost last: where [`phase`] reports.
    static RUNS: RefCell<Vec<Arc<Shared>>> = const { RefCell::new(Vec::new()) };
}

/// Starts the progress of a run of `len` steps named `what` (see the module's documentation) on stderr;
/// it ends when dropped.
pub fn progress(len: u64, what: &str) -> Progress {
    let display = if std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        let style =
            indicatif::ProgressStyle::with_template("{msg} {bar:30} {pos}/{len} ({elapsed})")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar());
        let bar = indicatif::ProgressBar::new(len)
            .with_style(style)
            .with_message(what.to_owned());
        // The elapsed time moves through a long phase.
        bar.enable_steady_tick(Duration::from_millis(500));
        Display::Bar(bar)
    } else {
        Display::Lines(Box::new(|line| eprintln!("{line}")))
    };
    start(len, what, display, interval())
}

/// Starts a run of `len` steps named `what` shown on `display`; off a terminal, with lines at most
/// `interval` apart.
fn start(len: u64, what: &str, display: Display, interval: Duration) -> Progress {
    let now = Instant::now();
    let shared = Arc::new(Shared {
        what: what.to_owned(),
        len,
        start: now,
        interval,
        state: Mutex::new(State {
            done: 0,
            message: String::new(),
            announced: false,
            phases: Vec::new(),
            next_phase: 0,
            last_line: now,
            finished: false,
        }),
        wake: Condvar::new(),
        display,
    });
    let heartbeat = matches!(shared.display, Display::Lines(_)).then(|| {
        let shared = Arc::clone(&shared);
        std::thread::spawn(move || shared.heartbeat())
    });
    RUNS.with(|runs| runs.borrow_mut().push(Arc::clone(&shared)));
    Progress {
        shared,
        heartbeat,
        _same_thread: PhantomData,
    }
}

/// Opens a phase of the current step of the innermost run on this thread: `len` units of work named
/// `name` (counts are shown when `len` is more than 1). Off a terminal its line is printed now. The phase
/// ends when the returned handle is dropped; without a run (or after it finished) it does nothing.
pub fn phase(name: impl Into<String>, len: u64) -> Phase {
    let Some(run) = RUNS.with(|runs| runs.borrow().last().cloned()) else {
        return Phase { run: None, id: 0 };
    };
    let mut state = run.lock();
    if state.finished {
        return Phase { run: None, id: 0 };
    }
    let id = state.next_phase;
    state.next_phase += 1;
    state.phases.push(PhaseState {
        id,
        name: name.into(),
        len,
        done: 0,
        start: Instant::now(),
    });
    run.show(&mut state);
    drop(state);
    Phase { run: Some(run), id }
}

/// A run's progress; see [`progress`].
pub struct Progress {
    shared: Arc<Shared>,
    heartbeat: Option<JoinHandle<()>>,
    /// The run stays on the thread that started it (it is this thread's innermost run until dropped).
    _same_thread: PhantomData<*const ()>,
}

/// A phase of a step; see [`phase`]. It may be counted from any thread.
pub struct Phase {
    run: Option<Arc<Shared>>,
    id: u64,
}

/// Where a run shows its progress.
enum Display {
    /// A bar (on a terminal).
    Bar(indicatif::ProgressBar),
    /// Lines, each handed to this (stderr; a list in the tests).
    Lines(Box<dyn Fn(&str) + Send + Sync>),
}

/// What a run, its phases and its heartbeat share.
struct Shared {
    what: String,
    len: u64,
    start: Instant,
    interval: Duration,
    state: Mutex<State>,
    /// Wakes the heartbeat when the run ends.
    wake: Condvar,
    display: Display,
}

struct State {
    /// Steps done.
    done: u64,
    /// The current step's name.
    message: String,
    /// Whether the current step's line was printed.
    announced: bool,
    /// Open phases, outermost first.
    phases: Vec<PhaseState>,
    next_phase: u64,
    last_line: Instant,
    finished: bool,
}

struct PhaseState {
    id: u64,
    name: String,
    len: u64,
    done: u64,
    start: Instant,
}

impl Progress {
    /// Names the step that starts now (off a terminal: prints its line).
    pub fn set_message(&self, message: impl Into<String>) {
        let mut state = self.shared.lock();
        state.message = message.into();
        state.announced = true;
        self.shared.show(&mut state);
    }

    /// Marks `n` steps done (off a terminal: prints a line for a step that was not named).
    pub fn inc(&self, n: u64) {
        let mut state = self.shared.lock();
        state.done += n;
        state.phases.clear();
        match &self.shared.display {
            Display::Bar(bar) => bar.inc(n),
            Display::Lines(_) => {
                if !std::mem::replace(&mut state.announced, false) {
                    state.message = "done".to_owned();
                    let step = state.done;
                    self.shared.print(&mut state, step);
                }
            }
        }
        state.message.clear();
    }

    /// Runs `f`, which prints on the terminal, with the bar hidden meanwhile.
    pub fn suspend<R>(&self, f: impl FnOnce() -> R) -> R {
        match &self.shared.display {
            Display::Bar(bar) => bar.suspend(f),
            Display::Lines(_) => f(),
        }
    }

    /// Ends the run (clears the bar, stops the lines).
    pub fn finish_and_clear(&self) {
        let mut state = self.shared.lock();
        state.finished = true;
        self.shared.wake.notify_all();
        if let Display::Bar(bar) = &self.shared.display {
            bar.finish_and_clear();
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.finish_and_clear();
        if let Some(heartbeat) = self.heartbeat.take() {
            // The heartbeat only prints; a panic in it has nothing to hand on.
            let _ = heartbeat.join();
        }
        RUNS.with(|runs| {
            runs.borrow_mut()
                .retain(|run| !Arc::ptr_eq(run, &self.shared))
        });
    }
}

impl Phase {
    /// Marks `n` units of the phase done.
    pub fn inc(&self, n: u64) {
        let Some(run) = &self.run else { return };
        let mut state = run.lock();
        if let Some(phase) = state.phases.iter_mut().find(|p| p.id == self.id) {
            phase.done += n;
            run.update_bar(&state);
        }
    }
}

impl Drop for Phase {
    fn drop(&mut self) {
        let Some(run) = &self.run else { return };
        let mut state = run.lock();
        state.phases.retain(|p| p.id != self.id);
        run.update_bar(&state);
    }
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Shows the run's state: the bar's message on a terminal, else a line.
    fn show(&self, state: &mut State) {
        match &self.display {
            Display::Bar(bar) => bar.set_message(self.state_text(state)),
            Display::Lines(_) => self.print(state, (state.done + 1).min(self.len)),
        }
    }

    /// Puts the run's state in the bar's message (on a terminal, while the run lasts).
    fn update_bar(&self, state: &State) {
        match &self.display {
            Display::Bar(bar) if !state.finished => bar.set_message(self.state_text(state)),
            _ => {}
        }
    }

    /// Off a terminal: prints the line of `state` at step `step` (counted from 1).
    fn print(&self, state: &mut State, step: u64) {
        if let Display::Lines(out) = &self.display {
            out(&format!(
                "{} [{step}/{}] {} ({})",
                self.what,
                self.len,
                self.state_text(state),
                self.times(state)
            ));
            state.last_line = Instant::now();
        }
    }

    /// The step's name and its open phases: "model: CPU reference 412/1080, about 52 s left".
    fn state_text(&self, state: &State) -> String {
        let mut text = if state.message.is_empty() {
            "working".to_owned()
        } else {
            state.message.clone()
        };
        for phase in &state.phases {
            text.push_str(": ");
            text.push_str(&phase.name);
            if phase.len > 1 {
                text.push_str(&format!(" {}/{}", phase.done, phase.len));
                if let Some(left) = time_left(phase.start.elapsed(), phase.done, phase.len) {
                    text.push_str(&format!(", about {left:.0} s left"));
                }
            }
        }
        text
    }

    /// "12 s elapsed, about 30 s left" (the time left of the run, from the steps done).
    fn times(&self, state: &State) -> String {
        let elapsed = self.start.elapsed();
        match time_left(elapsed, state.done, self.len) {
            Some(left) => format!(
                "{:.0} s elapsed, about {left:.0} s left",
                elapsed.as_secs_f64()
            ),
            None => format!("{:.0} s elapsed", elapsed.as_secs_f64()),
        }
    }

    /// Off a terminal: prints the run's state whenever `interval` passes without a line, until the run
    /// ends.
    fn heartbeat(&self) {
        let mut state = self.lock();
        while !state.finished {
            let due = state.last_line + self.interval;
            let now = Instant::now();
            if now >= due {
                let step = (state.done + 1).min(self.len);
                self.print(&mut state, step);
            } else {
                state = self
                    .wake
                    .wait_timeout(state, due - now)
                    .unwrap_or_else(PoisonError::into_inner)
                    .0;
            }
        }
    }
}

/// Seconds left for `len` units when `done` took `elapsed` (`None` before the first or after the last).
fn time_left(elapsed: Duration, done: u64, len: u64) -> Option<f64> {
    (done > 0 && done < len).then(|| elapsed.as_secs_f64() / done as f64 * (len - done) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lines a run printed, with their times.
    type Lines = Arc<Mutex<Vec<(Instant, String)>>>;

    /// A run whose lines go to a list.
    fn listed(len: u64, what: &str, interval: Duration) -> (Progress, Lines) {
        let lines = Arc::new(Mutex::new(Vec::new()));
        let sink = Arc::clone(&lines);
        let display = Display::Lines(Box::new(move |line| {
            sink.lock().unwrap().push((Instant::now(), line.to_owned()))
        }));
        (start(len, what, display, interval), lines)
    }

    #[test]
    fn time_left_scales_the_rate_of_the_units_done() {
        assert_eq!(time_left(Duration::from_secs(10), 0, 4), None);
        assert_eq!(time_left(Duration::from_secs(10), 1, 4), Some(30.0));
        assert_eq!(time_left(Duration::from_secs(10), 4, 4), None);
    }

    /// Steps and phases print their lines as they start; phases nest and report to the innermost run,
    /// from any thread; without a run a phase does nothing.
    #[test]
    fn phases_report_to_the_innermost_run_and_nest() {
        let hour = Duration::from_secs(3600);
        let (outer, outer_lines) = listed(2, "outer", hour);
        let (inner, inner_lines) = listed(3, "inner", hour);
        inner.set_message("model");
        let peer = phase("RT peer", 1);
        let frames = phase("frames", 4);
        frames.inc(1);
        let text = |run: &Progress| run.shared.state_text(&run.shared.lock());
        assert!(
            text(&inner).starts_with("model: RT peer: frames 1/4, about "),
            "{}",
            text(&inner)
        );
        drop(frames);
        assert_eq!(text(&inner), "model: RT peer");
        drop(peer);
        inner.inc(1);
        drop(inner);
        let printed: Vec<String> = inner_lines
            .lock()
            .unwrap()
            .iter()
            .map(|(_, l)| l.split(" (").next().unwrap_or_default().to_owned())
            .collect();
        assert_eq!(
            printed,
            [
                "inner [1/3] model",
                "inner [1/3] model: RT peer",
                "inner [1/3] model: RT peer: frames 0/4"
            ]
        );

        let rows = phase("CPU reference", 10);
        std::thread::scope(|s| {
            s.spawn(|| rows.inc(3));
        });
        assert_eq!(
            text(&outer).split(',').next(),
            Some("working: CPU reference 3/10")
        );
        drop(rows);
        drop(outer);
        assert_eq!(outer_lines.lock().unwrap().len(), 1);
        // Without a run a phase does nothing.
        phase("nothing", 2).inc(1);
    }

    /// Off a terminal, the run's state is printed again whenever the interval passes without a line:
    /// a long phase is never silent, and its lines carry its count and time left.
    #[test]
    fn a_silent_phase_gets_a_line_every_interval() {
        let interval = Duration::from_millis(200);
        let (run, lines) = listed(1, "bench", interval);
        run.set_message("model");
        let frames = phase("frames", 4);
        frames.inc(1);
        std::thread::sleep(Duration::from_millis(1100));
        drop(frames);
        drop(run);
        let lines = lines.lock().unwrap();
        assert!(lines.len() >= 4, "{lines:?}");
        for pair in lines.windows(2) {
            let gap = pair[1].0 - pair[0].0;
            assert!(gap < 3 * interval, "{gap:?} between {pair:?}");
        }
        let last = &lines.last().unwrap().1;
        assert!(
            last.starts_with("bench [1/1] model: frames 1/4, about ") && last.contains(" s left"),
            "{last}"
        );
    }
}
