//! The generators of the exponential flow ([`exponential`](super::exp_flow)) kept from one
//! point of a sweep to the next.
//!
//! A generator `Ã` of a piece depends on the basis, the state scales' ratio `ω_s` and the laws'
//! coefficients on the piece, not on the speed: along a run-up the same 40 or so come back at
//! every point. Its [`Core`] (the powers, `E_δ₀` and the doubling's sub-steps) and the
//! monodromy side's [`Propagator`] (the ladder `E_δ₀^{2^j}`, the powers `E_δ₀^m` met, the
//! Taylor terms `Ãⁱ/i!`) are kept, keyed by the bits of `δ₀`, the halvings and `Ã`; only the
//! load's part `X_δ₀` is formed again at each point. A kept core is the one the point would
//! have formed, to the last bit. Only the generators the last analysis used are kept.

use super::expm::ExpWork;
use super::generator::Core;
use super::propagator::Propagator;
use nalgebra::DMatrix;
use std::collections::HashMap;
use std::sync::Arc;

/// A hash of the words of a key of bits (rotate, xor, multiply by an odd constant per word):
/// the keys here are hundreds of words whose every bit matters, where SipHash cost a
/// microsecond a key.
#[derive(Default, Clone, Copy)]
pub(crate) struct WordHasher(u64);

impl std::hash::Hasher for WordHasher {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut word = [0u8; 8];
            word[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(word));
        }
    }

    fn write_u64(&mut self, word: u64) {
        self.0 = (self.0.rotate_left(5) ^ word).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }

    fn write_usize(&mut self, word: usize) {
        self.write_u64(word as u64);
    }
}

/// A map keyed by words with [`WordHasher`].
pub(crate) type WordMap<K, V> = HashMap<K, V, std::hash::BuildHasherDefault<WordHasher>>;

/// The generators of the last analysis, for the next.
#[derive(Clone, Default)]
pub(crate) struct KeptGenerators {
    /// Cores by a hash of the bits of `(δ₀, f, Ã)` ([`Core::is`] checks them).
    cores: WordMap<u64, Arc<Core>>,
    /// Propagators by their core's address.
    propagators: HashMap<usize, Propagator>,
}

impl std::fmt::Debug for KeptGenerators {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "KeptGenerators {{ cores: {}, propagators: {} }}",
            self.cores.len(),
            self.propagators.len()
        )
    }
}

/// The hash of a core's key: the bits of `δ₀`, `f` and `Ã`.
fn key(a: &DMatrix<f64>, delta0: f64, fine: u32) -> u64 {
    use std::hash::Hasher;
    let mut h = WordHasher::default();
    h.write_u64(delta0.to_bits());
    h.write_u64(fine as u64);
    for v in a.iter() {
        h.write_u64(v.to_bits());
    }
    h.finish()
}

/// A core's address, the key of its propagator.
fn address(core: &Arc<Core>) -> usize {
    Arc::as_ptr(core) as usize
}

/// The cores of one analysis: the kept ones it meets again and the new ones.
#[derive(Default)]
pub(crate) struct Cores {
    kept: WordMap<u64, Arc<Core>>,
    used: WordMap<u64, Arc<Core>>,
}

impl Cores {
    /// The core of `a` with sub-step `delta0` and `fine` halvings: kept, or formed.
    pub(crate) fn core(
        &mut self,
        a: DMatrix<f64>,
        delta0: f64,
        fine: u32,
        work: &mut ExpWork,
    ) -> Arc<Core> {
        let k = key(&a, delta0, fine);
        if let Some(c) = self.used.get(&k).filter(|c| c.is(&a, delta0, fine)) {
            return c.clone();
        }
        let c = match self.kept.remove(&k) {
            Some(c) if c.is(&a, delta0, fine) => c,
            _ => Arc::new(Core::new(a, delta0, fine, work)),
        };
        self.used.insert(k, c.clone());
        c
    }
}

impl KeptGenerators {
    /// Splits into the cores (for the flow) and the propagators (for its assembler).
    pub(crate) fn split(self) -> (Cores, HashMap<usize, Propagator>) {
        (
            Cores {
                kept: self.cores,
                used: WordMap::default(),
            },
            self.propagators,
        )
    }

    /// What an analysis leaves for the next: the cores it used and their propagators.
    pub(crate) fn join(cores: Cores, propagators: Vec<Propagator>) -> Self {
        let live: std::collections::HashSet<usize> = cores.used.values().map(address).collect();
        let propagators = propagators
            .into_iter()
            .filter(|p| live.contains(&address(p.core())))
            .map(|p| (address(p.core()), p))
            .collect();
        Self {
            cores: cores.used,
            propagators,
        }
    }
}

/// The propagator of `core`: kept, or new.
pub(crate) fn propagator(spare: &mut HashMap<usize, Propagator>, core: Arc<Core>) -> Propagator {
    spare
        .remove(&address(&core))
        .unwrap_or_else(|| Propagator::new(core))
}
