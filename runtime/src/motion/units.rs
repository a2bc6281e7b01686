//! The length unit of a clip, guessed from its skeleton height, for writers and engines that fix
//! one (glTF and Bevy are in metres).

/// What a file's unit was taken to be.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum UnitGuess {
    /// A figure 0.3-3 units tall: metres.
    Metres,
    /// A figure 30-300 units tall: centimetres.
    Centimetres,
    /// A figure 3-30 units tall: taken as CMU's motion-capture unit (1/0.45 inch, 0.0564 m),
    /// which puts a CMU human at 1.3-1.7 m; decimetres and inches are possible too.
    CmuUnits,
    /// Anything else: one unit is taken as a metre.
    Unknown,
}

/// The size of CMU's motion-capture unit in metres (1/0.45 inch).
pub const CMU_UNIT_METRES: f64 = 0.0254 / 0.45;

impl UnitGuess {
    /// The guess for a figure `height` file units tall.
    pub fn from_height(height: f64) -> UnitGuess {
        match height {
            h if (0.3..=3.0).contains(&h) => UnitGuess::Metres,
            h if (30.0..=300.0).contains(&h) => UnitGuess::Centimetres,
            h if (3.0..30.0).contains(&h) => UnitGuess::CmuUnits,
            _ => UnitGuess::Unknown,
        }
    }

    /// Metres per file unit.
    pub fn metres_per_unit(self) -> f64 {
        match self {
            UnitGuess::Metres | UnitGuess::Unknown => 1.0,
            UnitGuess::Centimetres => 0.01,
            UnitGuess::CmuUnits => CMU_UNIT_METRES,
        }
    }

    /// Whether the guess is a real reading (metres or centimetres) rather than a default.
    pub fn is_sure(self) -> bool {
        matches!(self, UnitGuess::Metres | UnitGuess::Centimetres)
    }

    /// The guess in words.
    pub fn describe(self) -> &'static str {
        match self {
            UnitGuess::Metres => "metres (a 0.3-3 m tall figure)",
            UnitGuess::Centimetres => "centimetres (a 30-300 cm tall figure)",
            UnitGuess::CmuUnits => {
                "unsure: taken as CMU units (0.0564 m; decimetres or inches are possible too)"
            }
            UnitGuess::Unknown => "unknown: one unit taken as a metre",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heights_map_to_units() {
        assert_eq!(UnitGuess::from_height(1.7), UnitGuess::Metres);
        assert_eq!(UnitGuess::from_height(170.0), UnitGuess::Centimetres);
        assert_eq!(UnitGuess::from_height(23.4), UnitGuess::CmuUnits);
        assert_eq!(UnitGuess::from_height(1000.0), UnitGuess::Unknown);
        // The CMU walk, 23.4 units tall, becomes a 1.32 m figure.
        assert!((23.4 * UnitGuess::CmuUnits.metres_per_unit() - 1.3208).abs() < 1e-3);
    }
}
