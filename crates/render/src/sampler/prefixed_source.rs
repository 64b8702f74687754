//! A [`RandomSource`] that hands a BSDF's `sample` routine its path vertex's dimensions.
//!
//! Why: a BSDF's `sample` draws its numbers from a `RandomSource`: one number to choose a
//! lobe and a pair for the direction — in either order, depending on the model — then, for
//! stochastic models, any number of further draws. The integrator wants the lobe number and
//! the direction pair to be the vertex's stratified/low-discrepancy dimensions (the pair a
//! 2D point of one scrambled (0, 2)-sequence, so that it stays stratified in 2D) and the
//! rest to come from the sample's free PCG stream. Matching by kind of call rather than by
//! position gives every model the right dimensions without the BSDF knowing about samplers.
//!
//! The two prefix values are drawn when the model first asks for them: a model that never
//! draws a lobe number (one lobe) costs the sampler nothing for it. Their values do not
//! depend on when they are drawn (a dimension's value is a function of the dimension).

use super::SampleStream;
use facette_bsdf::math::rng::RandomSource;
use glam::DVec2;

/// One prefix value: its dimension until drawn, then taken.
#[derive(Clone, Copy, Debug)]
enum Prefix {
    Dimension(u32),
    Taken,
}

/// Its first `next_f64` call returns the lobe dimension's value, its first `next_2d` call
/// the direction pair's; every other call draws from the sample's free PCG stream.
pub struct PrefixedSource<'a> {
    lobe: Prefix,
    direction: Prefix,
    stream: &'a mut SampleStream,
}

impl<'a> PrefixedSource<'a> {
    /// The lobe number at dimension `lobe_dimension` of `stream`, the direction pair at the
    /// two dimensions after it.
    pub fn new(stream: &'a mut SampleStream, lobe_dimension: u32) -> Self {
        PrefixedSource {
            lobe: Prefix::Dimension(lobe_dimension),
            direction: Prefix::Dimension(lobe_dimension + 1),
            stream,
        }
    }
}

impl RandomSource for PrefixedSource<'_> {
    #[inline]
    fn next_f64(&mut self) -> f64 {
        match std::mem::replace(&mut self.lobe, Prefix::Taken) {
            Prefix::Dimension(d) => {
                self.stream.set_dimension(d);
                self.stream.get_1d()
            }
            Prefix::Taken => self.stream.rng().next_f64(),
        }
    }

    #[inline]
    fn next_2d(&mut self) -> DVec2 {
        match std::mem::replace(&mut self.direction, Prefix::Taken) {
            Prefix::Dimension(d) => {
                self.stream.set_dimension(d);
                self.stream.get_2d()
            }
            Prefix::Taken => self.stream.rng().next_2d(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::{PixelSampler, SamplerKind};

    fn stream(kind: SamplerKind) -> SampleStream {
        PixelSampler::new(kind, 7, 16, 16, 64).stream(3, 5, 11)
    }

    /// The lobe number and the direction pair are the stream's dimensions d and (d+1, d+2)
    /// whichever is asked first, drawn or not; further draws come from the PCG stream.
    #[test]
    fn sampler_prefixed_source_takes_the_vertex_dimensions_in_either_order() {
        for kind in [
            SamplerKind::Sobol,
            SamplerKind::Stratified,
            SamplerKind::Independent,
        ] {
            let mut expected = stream(kind);
            expected.set_dimension(9);
            let (lobe, dir) = (expected.get_1d(), expected.get_2d());
            let mut reference = expected.rng().clone();

            let mut s = stream(kind);
            let mut src = PrefixedSource::new(&mut s, 9);
            assert_eq!(src.next_2d(), dir, "{kind:?}");
            assert_eq!(src.next_f64(), lobe, "{kind:?}");
            assert_eq!(src.next_f64(), reference.next_f64());
            assert_eq!(src.next_2d(), reference.next_2d());

            // A one-lobe model draws only its direction: the lobe's dimension is not
            // computed, and the direction is the same pair.
            let mut s = stream(kind);
            let mut src = PrefixedSource::new(&mut s, 9);
            assert_eq!(src.next_2d(), dir);
            let mut reference = s.rng().clone();
            let mut src = PrefixedSource::new(&mut s, 9);
            assert_eq!(src.next_f64(), lobe);
            assert_eq!(src.next_2d(), dir);
            assert_eq!(src.next_f64(), reference.next_f64());
        }
    }
}
