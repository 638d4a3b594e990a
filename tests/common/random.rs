//! Deterministic pseudo-random numbers for tests.

use lookdev::shading::sobol::hash_u32;

/// A counter-based generator: the n-th draw is a hash of (stream, n).
pub struct Random {
    state: u32,
    stream: u32,
}

impl Random {
    pub fn new(stream: u32) -> Random {
        Random { state: 0, stream: hash_u32(stream ^ 0x5bd1_e995) }
    }

    pub fn next_u32(&mut self) -> u32 {
        self.state = self.state.wrapping_add(1);
        hash_u32(hash_u32(self.state) ^ self.stream)
    }

    /// Uniform in [0, 1) with 24 bits.
    pub fn uniform(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 / 16_777_216.0
    }

    /// Uniform in [0, 1) with 53 bits.
    pub fn uniform_f64(&mut self) -> f64 {
        let hi = (self.next_u32() >> 5) as u64;
        let lo = (self.next_u32() >> 6) as u64;
        ((hi << 26) | lo) as f64 / (1u64 << 53) as f64
    }

    /// A uniformly distributed unit vector.
    pub fn direction(&mut self) -> glam::Vec3 {
        let z = 1.0 - 2.0 * self.uniform();
        let phi = 2.0 * std::f32::consts::PI * self.uniform();
        let r = (1.0 - z * z).max(0.0).sqrt();
        glam::Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }
}
