//! Options with a closed set of values, each known by one name: the names the command line,
//! the Python package and the reports use, declared once beside the option's type.
//!
//! A type lists its values in [`Choice::VALUES`] (value, name, one line of help); parsing,
//! naming, the list in an error and the command line's choices with their help all read that
//! table, so the fronts never spell the names again.
//!
//! ```
//! use subd_mesh::BoundaryInterpolation;
//! use subd_mesh::choice::Choice;
//!
//! let b: BoundaryInterpolation = "edge-and-corner".parse().unwrap();
//! assert_eq!(b, BoundaryInterpolation::EdgeAndCorner);
//! assert_eq!(b.name(), "edge-and-corner");
//! let e = "edges".parse::<BoundaryInterpolation>().unwrap_err();
//! assert_eq!(
//!     e.to_string(),
//!     "unknown boundary interpolation \"edges\" (one of none, edge-only, edge-and-corner)"
//! );
//! ```

use thiserror::Error;

/// A value that is not one of an option's names.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error("unknown {option} {given:?} (one of {names})")]
pub struct UnknownChoice {
    /// What the option is ([`Choice::OPTION`]).
    pub option: &'static str,
    /// The name given.
    pub given: String,
    /// The names it could have been, comma-separated.
    pub names: String,
}

/// An option with a closed set of values known by name.
pub trait Choice: Copy + PartialEq + Sized + 'static {
    /// What the option is, as an error message names it (`boundary interpolation`).
    const OPTION: &'static str;
    /// Every value with its name and one line of help, in the order they are listed.
    const VALUES: &'static [(Self, &'static str, &'static str)];
    /// Older spellings still accepted, with the value each means (not listed).
    const ALIASES: &'static [(&'static str, Self)] = &[];

    /// The value's name.
    fn name(self) -> &'static str {
        Self::row(self).1
    }

    /// The value's line of help.
    fn help(self) -> &'static str {
        Self::row(self).2
    }

    /// The value's row of [`Choice::VALUES`].
    fn row(self) -> &'static (Self, &'static str, &'static str) {
        Self::VALUES
            .iter()
            .find(|row| row.0 == self)
            .expect("every value of a choice is listed in its VALUES")
    }

    /// Every name, in order.
    fn names() -> impl Iterator<Item = &'static str> {
        Self::VALUES.iter().map(|row| row.1)
    }

    /// The value named `name` (or one of its aliases).
    ///
    /// # Errors
    /// [`UnknownChoice`] listing the names.
    fn from_name(name: &str) -> Result<Self, UnknownChoice> {
        let listed = Self::VALUES
            .iter()
            .find(|row| row.1 == name)
            .map(|row| row.0);
        let aliased = || Self::ALIASES.iter().find(|a| a.0 == name).map(|a| a.1);
        listed.or_else(aliased).ok_or_else(|| UnknownChoice {
            option: Self::OPTION,
            given: name.to_owned(),
            names: Self::names().collect::<Vec<_>>().join(", "),
        })
    }
}

/// `FromStr` and `Display` for a [`Choice`], by its names.
#[macro_export]
macro_rules! choice_by_name {
    ($t:ty) => {
        impl ::std::str::FromStr for $t {
            type Err = $crate::choice::UnknownChoice;
            fn from_str(s: &str) -> Result<Self, Self::Err> {
                <$t as $crate::choice::Choice>::from_name(s)
            }
        }
        impl ::std::fmt::Display for $t {
            fn fmt(&self, f: &mut ::std::fmt::Formatter<'_>) -> ::std::fmt::Result {
                f.write_str($crate::choice::Choice::name(*self))
            }
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fvar::FVarLinearInterpolation;
    use crate::{BoundaryInterpolation, CreaseMethod, TriangleSubdivision};

    /// Every listed name parses back to its value, and the names are distinct.
    fn round_trips<T: Choice + std::fmt::Debug>() {
        for &(value, name, help) in T::VALUES {
            assert_eq!(T::from_name(name), Ok(value));
            assert_eq!(value.name(), name);
            assert!(!help.is_empty(), "{name} has no help");
        }
        let mut names: Vec<_> = T::names().collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), T::VALUES.len());
    }

    #[test]
    fn the_rule_options_round_trip_by_name() {
        round_trips::<BoundaryInterpolation>();
        round_trips::<CreaseMethod>();
        round_trips::<TriangleSubdivision>();
        round_trips::<FVarLinearInterpolation>();
    }

    #[test]
    fn the_fvar_modes_keep_opensubdivs_order() {
        // `Sdc::Options::FVarLinearInterpolation`: the shape tag's value is the position.
        use FVarLinearInterpolation as M;
        let osd = [
            M::None,
            M::CornersOnly,
            M::CornersPlus1,
            M::CornersPlus2,
            M::Boundaries,
            M::All,
        ];
        assert_eq!(M::ALL_MODES, osd);
        assert_eq!(M::from_shape_tag(2), Some(M::CornersPlus1));
    }

    #[test]
    fn an_unknown_name_lists_the_names() {
        let e = "cubic".parse::<CreaseMethod>().unwrap_err();
        assert_eq!(e.option, "crease method");
        assert_eq!(e.names, "uniform, chaikin");
        assert!(e.to_string().contains("\"cubic\""));
    }
}
