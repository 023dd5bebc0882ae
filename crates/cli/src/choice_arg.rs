//! Command-line values of the library's named options ([`Choice`]): the choices, their help
//! and their older spellings all come from the option's own table.

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use subd_mesh::choice::Choice;

/// The parser of an option whose values are `T`'s names.
pub(crate) fn parser<T: Choice + Send + Sync>() -> impl TypedValueParser<Value = T> {
    let values = T::VALUES.iter().map(|&(value, name, help)| {
        let aliases = T::ALIASES.iter().filter(|a| a.1 == value).map(|a| a.0);
        PossibleValue::new(name).help(help).aliases(aliases)
    });
    PossibleValuesParser::new(values).try_map(|name| T::from_name(&name))
}
