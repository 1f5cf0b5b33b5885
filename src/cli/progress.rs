//! Progress of long runs on a terminal: a spinner on standard error showing the stage and
//! its count (`sampling: 12,345 points, 210 curves`, `validating 1,046,026 triangles`,
//! `writing x.ply`), from the library's [`Progress`] reports and the command's own steps.
//!
//! It appears only after [`DELAY`], only when standard error is a terminal, and never with
//! `--quiet`; it is cleared before the summary is printed, so a pipe or a file gets the
//! summary alone.

use liemesh::{Progress, Stage};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// How long a run goes before the spinner appears: shorter runs show nothing.
pub const DELAY: Duration = Duration::from_secs(1);

/// How often the spinner reads the latest status.
const REFRESH: Duration = Duration::from_millis(100);

/// What the run is doing now: written by the work as it goes, read by the spinner.
#[derive(Debug, Default)]
pub struct Status {
    shown: Mutex<Shown>,
}

#[derive(Clone, Debug, Default, PartialEq)]
enum Shown {
    /// Nothing reported yet.
    #[default]
    Starting,
    /// A report of the library's pipeline.
    Run(Progress),
    /// A step of the command's own (`writing x.ply`).
    Text(String),
}

impl Status {
    /// Records a report of the meshing pipeline (the observer passed to
    /// `liemesh::run_observed`).
    pub fn report(&self, progress: Progress) {
        *self.lock() = Shown::Run(progress);
    }

    /// Records a step of the command's own, in words (`writing x.ply`).
    pub fn step(&self, text: impl Into<String>) {
        *self.lock() = Shown::Text(text.into());
    }

    /// The line the spinner shows.
    pub fn message(&self) -> String {
        match &*self.lock() {
            Shown::Starting => "starting".into(),
            Shown::Run(p) => describe(p),
            Shown::Text(t) => t.clone(),
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Shown> {
        // A panic while the lock was held left a whole value behind: showing it is fine.
        self.shown
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }
}

/// A report of the pipeline in words.
pub fn describe(p: &Progress) -> String {
    let n = |count: usize, one: &str, many: &str| {
        format!("{} {}", grouped(count), if count == 1 { one } else { many })
    };
    match p.stage {
        Stage::Sampling => format!(
            "sampling: {}, {}",
            n(p.points, "point", "points"),
            n(p.curves, "curve", "curves")
        ),
        Stage::Triangulating => format!("triangulating {}", n(p.points, "point", "points")),
        Stage::Refining if p.round == 0 => {
            format!("refining {}", n(p.triangles, "triangle", "triangles"))
        }
        Stage::Refining => format!(
            "refining: round {}, {}",
            p.round,
            n(p.triangles, "triangle", "triangles")
        ),
        stage => format!("{stage} {}", n(p.triangles, "triangle", "triangles")),
    }
}

/// `n` with its digits in groups of three: `1,046,026`.
pub fn grouped(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::with_capacity(digits.len() + digits.len() / 3);
    for (i, d) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(d);
    }
    out
}

/// Runs `work`, which reports what it is doing to the [`Status`] it is given; if it takes
/// longer than [`DELAY`], standard error is a terminal and not `quiet`, a spinner shows the
/// latest status until `work` returns (and is then cleared).
pub fn with_progress<R>(quiet: bool, work: impl FnOnce(&Status) -> R) -> R {
    use std::io::IsTerminal;
    let status = Status::default();
    if quiet || !std::io::stderr().is_terminal() {
        return work(&status);
    }
    let start = Instant::now();
    let (done, finished) = mpsc::channel::<()>();
    std::thread::scope(|scope| {
        let status = &status;
        scope.spawn(move || spin(status, &finished, start));
        let result = work(status);
        // The spinner ends on this message, or on the channel's closing if `work` panicked.
        let _ = done.send(());
        result
    })
}

/// The spinner: waits [`DELAY`] from `start`, then shows the status every [`REFRESH`] until
/// `finished` says the work is done.
fn spin(status: &Status, finished: &mpsc::Receiver<()>, start: Instant) {
    if !matches!(
        finished.recv_timeout(DELAY.saturating_sub(start.elapsed())),
        Err(RecvTimeoutError::Timeout)
    ) {
        return;
    }
    let style = indicatif::ProgressStyle::with_template("{spinner} {msg} ({elapsed})")
        .expect("the template is valid");
    let bar = indicatif::ProgressBar::new_spinner()
        .with_style(style)
        .with_elapsed(start.elapsed())
        .with_message(status.message());
    bar.enable_steady_tick(REFRESH);
    while let Err(RecvTimeoutError::Timeout) = finished.recv_timeout(REFRESH) {
        bar.set_message(status.message());
    }
    bar.finish_and_clear();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_are_grouped_by_thousands() {
        assert_eq!(grouped(0), "0");
        assert_eq!(grouped(999), "999");
        assert_eq!(grouped(1000), "1,000");
        assert_eq!(grouped(12345), "12,345");
        assert_eq!(grouped(1046026), "1,046,026");
    }

    #[test]
    fn status_shows_the_latest_report_in_words() {
        let status = Status::default();
        assert_eq!(status.message(), "starting");
        // The reports of a real run, as they come.
        let sphere =
            liemesh::model::Invariant::from_numbers(&[1.0, 1.0, 1.0, 0.0, 0.0, 0.0]).unwrap();
        let field = liemesh::model::LieField::<f64>::new(&sphere);
        let mut params = liemesh::preset::Preset::Fig3.params();
        params.max_normal_error = Some(liemesh::Angle::from_degrees(1.0));
        let seen = std::cell::RefCell::new(Vec::new());
        liemesh::run_observed(&field, &params, &|p| {
            status.report(p);
            seen.borrow_mut().push(status.message());
        })
        .unwrap();
        let seen = seen.into_inner();
        // p0 and the six curves of the proposed method's first fan.
        assert_eq!(seen[0], "sampling: 1 point, 6 curves");
        for prefix in [
            "triangulating ",
            "stitching ",
            "improving ",
            "refining: round 1, ",
            "validating ",
        ] {
            assert!(
                seen.iter().any(|m| m.starts_with(prefix)),
                "no '{prefix}…' in {seen:?}"
            );
        }
        assert!(seen.last().unwrap().ends_with(" triangles"), "{seen:?}");
        status.step("writing x.ply");
        assert_eq!(status.message(), "writing x.ply");
    }
}
