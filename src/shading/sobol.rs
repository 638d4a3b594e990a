//! Mirror of `glsl/include/sobol.glsl`: Owen-scrambled Sobol points (Burley 2020).

use glam::Vec2;

/// Chris Wellons' lowbias32 integer hash, for seeds.
pub fn hash_u32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846ca68b);
    x ^= x >> 16;
    x
}

pub fn hash_combine(seed: u32, value: u32) -> u32 {
    hash_u32(seed ^ (value.wrapping_add(0x9e3779b9).wrapping_add(seed << 6).wrapping_add(seed >> 2)))
}

/// A Laine–Karras style permutation on bit-reversed integers.
pub fn laine_karras_permutation(mut x: u32, seed: u32) -> u32 {
    x ^= x.wrapping_mul(0x3d20adea);
    x = x.wrapping_add(seed);
    x = x.wrapping_mul((seed >> 16) | 1);
    x ^= x.wrapping_mul(0x05526c56);
    x ^= x.wrapping_mul(0x53a22864);
    x
}

pub fn nested_uniform_scramble(x: u32, seed: u32) -> u32 {
    laine_karras_permutation(x.reverse_bits(), seed).reverse_bits()
}

/// Sobol dimension 1 (primitive polynomial x + 1) by a superset XOR transform over bit
/// positions (see sobol.glsl); dimension 0 is `index.reverse_bits()`.
pub fn sobol_dimension1(index: u32) -> u32 {
    let mut z = index;
    z ^= (z >> 1) & 0x5555_5555;
    z ^= (z >> 2) & 0x3333_3333;
    z ^= (z >> 4) & 0x0f0f_0f0f;
    z ^= (z >> 8) & 0x00ff_00ff;
    z ^= (z >> 16) & 0x0000_ffff;
    z.reverse_bits()
}

/// 24 high bits to a float in [0, 1), exactly.
pub fn u32_to_unit_float(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// Point `index` of the Owen-scrambled 2D Sobol sequence for one pixel and one dimension group.
pub fn sobol_owen_2d(index: u32, seed: u32) -> Vec2 {
    let shuffled = nested_uniform_scramble(index, seed);
    let x = nested_uniform_scramble(shuffled.reverse_bits(), hash_combine(seed, 1));
    let y = nested_uniform_scramble(sobol_dimension1(shuffled), hash_combine(seed, 2));
    Vec2::new(u32_to_unit_float(x), u32_to_unit_float(y))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Direction numbers of Sobol dimension 1 by the textbook recurrence
    /// v_k = v_{k−1} ⊕ (v_{k−1} >> 1) from m_1 = 1 (Joe and Kuo's first polynomial).
    fn dimension1_by_matrix(index: u32) -> u32 {
        let mut v = [0u32; 32];
        v[0] = 1 << 31;
        for k in 1..32 {
            v[k] = v[k - 1] ^ (v[k - 1] >> 1);
        }
        (0..32).filter(|&b| index & (1 << b) != 0).fold(0, |acc, b| acc ^ v[b])
    }

    #[test]
    fn dimension1_matches_the_generator_matrix_and_known_values() {
        for i in (0..4096).chain((0..4096).map(|k: u32| k.wrapping_mul(0x9e37_79b9))) {
            assert_eq!(sobol_dimension1(i), dimension1_by_matrix(i), "index {i:#x}");
        }
        // The first points of Sobol dimension 1 in index (not Gray-code) order.
        let expected = [0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875];
        for (i, e) in expected.iter().enumerate() {
            assert_eq!(sobol_dimension1(i as u32) as f64 / 4294967296.0, *e);
        }
    }

    /// Every prefix of 2^m points of an Owen-scrambled (0,2)-sequence is a (0,m,2)-net: each
    /// elementary interval of area 2^−m holds exactly one point.
    #[test]
    fn scrambled_points_are_nets_in_every_elementary_interval() {
        for seed in [0u32, 1, 0xdead_beef, 12345] {
            for m in [4u32, 6, 8] {
                let n = 1u32 << m;
                let points: Vec<Vec2> = (0..n).map(|i| sobol_owen_2d(i, seed)).collect();
                for kx in 0..=m {
                    let ky = m - kx;
                    let mut counts = vec![0u32; n as usize];
                    for p in &points {
                        let cx = (p.x * (1u32 << kx) as f32) as u32;
                        let cy = (p.y * (1u32 << ky) as f32) as u32;
                        counts[(cy * (1 << kx) + cx) as usize] += 1;
                    }
                    assert!(counts.iter().all(|&c| c == 1), "seed {seed} m {m} kx {kx}: {counts:?}");
                }
            }
        }
    }

    #[test]
    fn different_seeds_give_different_points() {
        let a: Vec<Vec2> = (0..16).map(|i| sobol_owen_2d(i, 1)).collect();
        let b: Vec<Vec2> = (0..16).map(|i| sobol_owen_2d(i, 2)).collect();
        assert_ne!(a, b);
        assert!(a.iter().all(|p| (0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y)));
    }
}
