//! A [`RandomSource`] that hands a BSDF's `sample` routine its path vertex's dimensions.
//!
//! Why: a BSDF's `sample` draws its numbers from a `RandomSource`: one number to choose a
//! lobe and a pair for the direction — in either order, depending on the model — then, for
//! stochastic models, any number of further draws. The integrator wants the lobe number and
//! the direction pair to be the vertex's stratified/low-discrepancy dimensions (the pair a
//! 2D point of one scrambled (0, 2)-sequence, so that it stays stratified in 2D) and the
//! rest to come from the sample's free PCG stream. Matching by kind of call rather than by
//! position gives every model the right dimensions without the BSDF knowing about samplers.

use facette_bsdf::math::rng::{Pcg32, RandomSource};
use glam::DVec2;

/// Its first `next_f64` call returns `lobe`, its first `next_2d` call returns `direction`;
/// every other call draws from `rest`.
pub struct PrefixedSource<'a> {
    lobe: Option<f64>,
    direction: Option<DVec2>,
    rest: &'a mut Pcg32,
}

impl<'a> PrefixedSource<'a> {
    /// The values must lie in [0, 1), as every `RandomSource` value does.
    pub fn new(lobe: f64, direction: DVec2, rest: &'a mut Pcg32) -> Self {
        debug_assert!([lobe, direction.x, direction.y]
            .iter()
            .all(|v| (0.0..1.0).contains(v)));
        PrefixedSource {
            lobe: Some(lobe),
            direction: Some(direction),
            rest,
        }
    }
}

impl RandomSource for PrefixedSource<'_> {
    #[inline]
    fn next_f64(&mut self) -> f64 {
        match self.lobe.take() {
            Some(v) => v,
            None => self.rest.next_f64(),
        }
    }

    #[inline]
    fn next_2d(&mut self) -> DVec2 {
        match self.direction.take() {
            Some(v) => v,
            None => self.rest.next_2d(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sampler_prefixed_source_lobe_then_direction() {
        let mut rng = Pcg32::new(4, 2);
        let mut reference = rng.clone();
        {
            let mut src = PrefixedSource::new(0.25, DVec2::new(0.5, 0.75), &mut rng);
            assert_eq!(src.next_f64(), 0.25);
            assert_eq!(src.next_2d(), DVec2::new(0.5, 0.75));
            for _ in 0..5 {
                assert_eq!(src.next_f64(), reference.next_f64());
            }
            assert_eq!(src.next_2d(), reference.next_2d());
        }
        // The generator it borrowed has advanced by exactly the draws beyond the prefix.
        assert_eq!(rng.next_u32(), reference.next_u32());
    }

    #[test]
    fn sampler_prefixed_source_direction_first() {
        // A model that draws its direction before its lobe (the rough dielectric) still
        // gets the pair as its direction and the single number as its lobe.
        let mut rng = Pcg32::new(9, 1);
        let mut reference = rng.clone();
        let mut src = PrefixedSource::new(0.125, DVec2::new(0.375, 0.625), &mut rng);
        assert_eq!(src.next_2d(), DVec2::new(0.375, 0.625));
        assert_eq!(src.next_f64(), 0.125);
        assert_eq!(src.next_f64(), reference.next_f64());
    }
}
