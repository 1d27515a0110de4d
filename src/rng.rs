//! Seeded, order-free randomness: every random number is a hash of
//! (seed, stream, index), never the state of a shared generator, so results
//! do not depend on the order or thread in which they are drawn.

/// SplitMix64's finalizer: a bijective 64-bit mix with good avalanche.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A 64-bit hash of the key words, in order.
pub fn hash(words: &[u64]) -> u64 {
    words
        .iter()
        .fold(0x6A09_E667_F3BC_C909, |h, &w| mix(h ^ mix(w)))
}

/// A uniform number in [0, 1) from the key words.
pub fn unit(words: &[u64]) -> f64 {
    (hash(words) >> 11) as f64 / (1u64 << 53) as f64
}

/// A uniform index in 0..n (n > 0) from the key words.
pub fn index(words: &[u64], n: usize) -> usize {
    ((unit(words) * n as f64) as usize).min(n.saturating_sub(1))
}

#[cfg(test)]
mod tests {
    #[test]
    fn unit_is_spread() {
        let v: Vec<f64> = (0..1000).map(|i| super::unit(&[7, i])).collect();
        let mean = v.iter().sum::<f64>() / 1000.0;
        assert!((mean - 0.5).abs() < 0.05);
        assert!(v.iter().all(|x| (0.0..1.0).contains(x)));
    }
}
