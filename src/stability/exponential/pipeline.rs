//! The monodromy matrix multiplied on a second thread while the orbit is integrated.
//!
//! A pass of the exponential flow records its factors in order ([`record`](super::record));
//! with a link, every generator and every step is also sent to an [`Assembler`] on a scoped
//! thread, which multiplies them as they come. When the pass ends, its `Φ̃` is ready about as
//! soon as the orbit: the products (a third of a point's work on the drivetrain) overlap the
//! integration. The assembler applies the same factors in the same order as the sequential
//! replay of the record, so `Φ̃` is the same to the last bit, whatever the scheduling. A pass
//! whose `Φ̃` is not asked for (a chord step follows it) is abandoned when the next pass
//! begins.
//!
//! Used where the machine has at least two cores and `HBAL_THREADS` does not say 1
//! (`linear::parallel::second_thread`); otherwise the record is replayed after the pass.

use super::generator::Core;
use super::integration::Integration;
use super::record::{Assembler, Step};
use crate::error::{Error, Result};
use nalgebra::DMatrix;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc::{channel, Receiver, Sender};
use std::sync::Arc;

/// What the flow sends to the assembler.
pub(crate) enum Message {
    /// The next generator.
    Generator(Arc<Core>),
    /// A pass begins: `Φ̃ = I`.
    Begin(usize),
    /// The pass's next steps, in order.
    Steps(Vec<Step>),
    /// The pass ends: `Φ̃` goes back.
    End,
}

/// The flow's end of the link.
pub(crate) struct Link {
    to: Sender<Message>,
    from: Receiver<(usize, Result<DMatrix<f64>>)>,
    /// Passes up to this one are abandoned.
    abandoned: Arc<AtomicUsize>,
    /// The current pass (numbered from 1).
    pass: usize,
    /// The last `Φ̃` received, with its pass (asked for again, it is not waited for again).
    received: Option<(usize, Result<DMatrix<f64>>)>,
    /// Steps not sent yet: they go in batches of [`BATCH`], so that the assembler is not woken
    /// for every piece (one wake-up per step cost more than the step).
    pending: Vec<Step>,
}

/// Steps per message.
const BATCH: usize = 64;

impl Link {
    /// Sends `message` after the steps before it (a finished assembler is only possible after
    /// a panic, which the scope reports).
    pub(crate) fn send(&mut self, message: Message) {
        self.flush();
        let _ = self.to.send(message);
    }

    /// Queues the pass's next step.
    pub(crate) fn step(&mut self, step: Step) {
        self.pending.push(step);
        if self.pending.len() >= BATCH {
            self.flush();
        }
    }

    fn flush(&mut self) {
        if !self.pending.is_empty() {
            let steps = std::mem::replace(&mut self.pending, Vec::with_capacity(BATCH));
            let _ = self.to.send(Message::Steps(steps));
        }
    }

    /// A new pass; the last one's `Φ̃` is no longer wanted (nor its unsent steps).
    pub(crate) fn begin(&mut self) {
        self.pending.clear();
        self.abandoned.store(self.pass, Ordering::Relaxed);
        self.pass += 1;
        self.send(Message::Begin(self.pass));
    }

    /// `Φ̃` of the current pass (after [`Message::End`]).
    pub(crate) fn monodromy(&mut self) -> Result<DMatrix<f64>> {
        loop {
            if let Some((pass, phi)) = &self.received {
                if *pass == self.pass {
                    return phi.clone();
                }
            }
            match self.from.recv() {
                Ok(reply) => self.received = Some(reply),
                Err(_) => {
                    return Err(Error::Solver {
                        reason: "the monodromy matrix's thread stopped".into(),
                    })
                }
            }
        }
    }
}

impl Assembler {
    /// Serves a link until the flow drops it, then gives itself back.
    fn serve(
        mut self: Box<Self>,
        messages: Receiver<Message>,
        replies: Sender<(usize, Result<DMatrix<f64>>)>,
        abandoned: Arc<AtomicUsize>,
    ) -> Box<Self> {
        let mut pass = 0;
        for message in messages {
            match message {
                Message::Generator(core) => self.add(core),
                Message::Begin(p) => {
                    pass = p;
                    self.begin();
                }
                Message::Steps(steps) => {
                    for step in &steps {
                        if abandoned.load(Ordering::Relaxed) >= pass {
                            break;
                        }
                        self.apply(step);
                    }
                }
                Message::End => {
                    if abandoned.load(Ordering::Relaxed) < pass {
                        let _ = replies.send((pass, self.finish()));
                    }
                }
            }
        }
        self
    }
}

/// `true` where a second thread can run.
fn parallel() -> bool {
    #[cfg(test)]
    if let Some(forced) = tests::FORCE.with(|f| f.get()) {
        return forced;
    }
    crate::linear::parallel::second_thread()
}

impl<'c, 'm> Integration<'c, 'm> {
    /// Runs `work` on this flow with its assembler on a second thread (exponential flow, two
    /// cores), or as it is.
    pub(crate) fn with_assembler<R>(&mut self, work: impl FnOnce(&mut Self) -> R) -> R {
        let Integration::Exponential { flow, .. } = self else {
            return work(self);
        };
        if !parallel() {
            return work(self);
        }
        let assembler = flow.take_assembler();
        let (to, messages) = channel();
        let (replies, from) = channel();
        let abandoned = Arc::new(AtomicUsize::new(0));
        let shared = abandoned.clone();
        flow.link(Link {
            to,
            from,
            abandoned,
            pass: 0,
            received: None,
            pending: Vec::with_capacity(BATCH),
        });
        std::thread::scope(|scope| {
            let handle = scope.spawn(move || assembler.serve(messages, replies, shared));
            // (A panic in `work` must still end the assembler's loop before the scope joins.)
            let out = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| work(self)));
            // Dropping the link ends the assembler's loop (also when the flow was replaced).
            let link = match self {
                Integration::Exponential { flow, .. } => flow.unlink(),
                Integration::RungeKutta { .. } => None,
            };
            drop(link);
            let assembler = handle
                .join()
                .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
            if let Integration::Exponential { flow, .. } = self {
                flow.restore_assembler(assembler);
            }
            out.unwrap_or_else(|panic| std::panic::resume_unwind(panic))
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::force::{Backlash, MeshProfile};
    use crate::{HarmonicBalance, HarmonicBasis, Model, Newton};
    use nalgebra::DMatrix;
    use std::cell::Cell;

    thread_local! {
        /// Forces the assembler onto a second thread (`Some(true)`) or not.
        pub(crate) static FORCE: Cell<Option<bool>> = const { Cell::new(None) };
    }

    /// A backlash chain with contact damping (force jumps, saltation matrices) whose shooting
    /// needs a few passes: the same multipliers and orbit to the last bit with the monodromy
    /// matrices multiplied on a second thread or after each pass.
    #[test]
    fn the_second_thread_gives_the_same_bits() {
        let k = DMatrix::from_row_slice(3, 3, &[2.0, -1.0, 0.0, -1.0, 2.0, -1.0, 0.0, -1.0, 1.0]);
        let contact =
            Backlash::new(1.0, MeshProfile::Constant { stiffness: 5.0 }).with_contact_damping(0.3);
        let model = Model::builder(&["x1", "x2", "x3"])
            .mass_diagonal(&[1.0, 1.0, 1.0])
            .damping(DMatrix::from_diagonal_element(3, 3, 0.08))
            .stiffness(k)
            .element("contact", &[("x2", -1.0), ("x3", 1.0)], contact)
            .load("x1", 1, 1.0, 0.0)
            .build()
            .unwrap();
        let hb = HarmonicBalance::new(&model, HarmonicBasis::new(1.36, 32).unwrap()).unwrap();
        let sol = Newton::new().solve(&hb, &mut hb.workspace()).unwrap();
        let run = |threaded| {
            FORCE.with(|f| f.set(Some(threaded)));
            let out = crate::stability::floquet(&model, &sol).unwrap();
            FORCE.with(|f| f.set(None));
            out
        };
        let (threaded, here) = (run(true), run(false));
        assert!(threaded.polished && threaded.steps > 0);
        assert_eq!(threaded, here);
    }
}
