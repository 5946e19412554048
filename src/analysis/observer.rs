//! Progress of a long analysis, reported to the caller: the CLI's progress bar, a notebook's
//! widget, a log. Cancellation goes the other way, through the settings' [`Cancel`] token.
//!
//! [`Cancel`]: crate::continuation::Cancel

/// Receives the progress of an analysis. Every method has an empty default.
///
/// ```
/// use hbal::analysis::Observer;
/// struct Log(Vec<f64>);
/// impl Observer for Log {
///     fn progress(&mut self, fraction: f64) {
///         self.0.push(fraction);
///     }
/// }
/// let mut log = Log(Vec::new());
/// log.progress(0.5);
/// log.stage("switching branches");
/// assert_eq!(log.0, [0.5]);
/// ```
pub trait Observer {
    /// The fraction in `[0, 1]` of the current stage done (a sweep: of its speed range).
    fn progress(&mut self, fraction: f64) {
        let _ = fraction;
    }

    /// A new stage of the work begins (e.g. `switching branches`).
    fn stage(&mut self, what: &str) {
        let _ = what;
    }
}

/// An observer that ignores everything.
#[derive(Debug, Clone, Copy, Default)]
pub struct Silent;

impl Observer for Silent {}
