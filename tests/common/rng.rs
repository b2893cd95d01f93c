//! xorshift64*: the hostile-input tests' mutants are the same on every run. Included with
//! the suite (`use crate::rng`) and by the hostile binaries with `#[path]`.

pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    /// A whole number below `n` (0 for `n` = 0).
    #[allow(dead_code)] // not every test that includes this file draws whole numbers
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}
