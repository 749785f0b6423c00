//! A coordinate as a hash key: its exact bits, so that points shared by
//! construction (a vertex of two rings, the end of a leg) meet in a hash map
//! without a tolerance. `0.0` and `-0.0` are different keys, as their bits
//! are; a caller that may meet both adds `0.0` first.

use geo::Coord;

/// The bits of a coordinate's x and y.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct CoordKey(u64, u64);

impl From<Coord<f64>> for CoordKey {
    fn from(c: Coord<f64>) -> Self {
        Self(c.x.to_bits(), c.y.to_bits())
    }
}

impl From<&Coord<f64>> for CoordKey {
    fn from(c: &Coord<f64>) -> Self {
        Self::from(*c)
    }
}

impl CoordKey {
    /// The coordinate back.
    pub fn coord(self) -> Coord<f64> {
        Coord {
            x: f64::from_bits(self.0),
            y: f64::from_bits(self.1),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equal_coordinates_are_one_key_and_signed_zeros_two() {
        let k = |x: f64, y: f64| CoordKey::from(Coord { x, y });
        assert_eq!(k(1.5, -2.0), k(1.5, -2.0));
        assert_ne!(k(1.5, -2.0), k(-2.0, 1.5));
        assert_ne!(k(0.0, 1.0), k(-0.0, 1.0));
        assert_eq!(k(-0.0 + 0.0, 1.0), k(0.0, 1.0));
        assert_eq!(k(-0.0, 2.5).coord().x.to_bits(), (-0.0f64).to_bits());
    }
}
