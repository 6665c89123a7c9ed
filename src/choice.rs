//! How a command, the library and a sweep task name the method of an algorithm: `auto`
//! (the algorithm picks the fastest exact method from its cost models) or one method.
//!
//! Each method enum derives `clap::ValueEnum`, whose names are the only spelling of its
//! methods: [`Choice`] parses and prints through them, and [`by_name`] / [`by_name_or_none`]
//! / [`choice_or_none`] (de)serialize a method, an optional one or an optional choice
//! (`none`) through them in a task's options.

use std::fmt;
use std::str::FromStr;

use clap::ValueEnum;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// `auto` or one method.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Choice<M> {
    #[default]
    Auto,
    Fixed(M),
}

impl<M: Copy> Choice<M> {
    /// The method, unless `auto`.
    pub fn fixed(self) -> Option<M> {
        match self {
            Choice::Auto => None,
            Choice::Fixed(m) => Some(m),
        }
    }
}

/// The name of `m` (as `--method` spells it).
pub fn name<M: ValueEnum>(m: &M) -> String {
    m.to_possible_value().map(|v| v.get_name().to_string()).unwrap_or_default()
}

/// The method named `s`.
pub fn parse<M: ValueEnum>(s: &str) -> Option<M> {
    M::value_variants().iter().find(|m| name(*m) == s).cloned()
}

/// Every method's name, comma-separated.
fn names<M: ValueEnum>() -> String {
    M::value_variants().iter().map(name).collect::<Vec<_>>().join(", ")
}

impl<M> From<M> for Choice<M> {
    fn from(m: M) -> Choice<M> {
        Choice::Fixed(m)
    }
}

/// The clap parser of a `--method` that takes a [`Choice`]: its possible values are `auto`
/// (described by `auto`) and every method of `M` with its doc line, so that `--help` and
/// usage errors list them as for a plain `clap::ValueEnum`.
pub fn value_parser<M: ValueEnum + Send + Sync + 'static>(
    auto: &'static str,
) -> impl clap::builder::TypedValueParser<Value = Choice<M>> {
    use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
    let values = std::iter::once(PossibleValue::new("auto").help(auto))
        .chain(M::value_variants().iter().filter_map(ValueEnum::to_possible_value));
    PossibleValuesParser::new(values).try_map(|s| s.parse::<Choice<M>>())
}

impl<M: ValueEnum> FromStr for Choice<M> {
    type Err = String;
    fn from_str(s: &str) -> Result<Choice<M>, String> {
        if s == "auto" {
            return Ok(Choice::Auto);
        }
        parse(s).map(Choice::Fixed).ok_or_else(|| format!("no method '{s}' (auto, {})", names::<M>()))
    }
}

impl<M: ValueEnum> fmt::Display for Choice<M> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Choice::Auto => f.write_str("auto"),
            Choice::Fixed(m) => f.write_str(&name(m)),
        }
    }
}

impl<M: ValueEnum> Serialize for Choice<M> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.to_string())
    }
}

impl<'de, M: ValueEnum> Deserialize<'de> for Choice<M> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Choice<M>, D::Error> {
        String::deserialize(d)?.parse().map_err(serde::de::Error::custom)
    }
}

/// `#[serde(with = "crate::choice::by_name")]`: a method by its name.
pub mod by_name {
    use super::*;

    pub fn serialize<M: ValueEnum, S: Serializer>(m: &M, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&name(m))
    }

    pub fn deserialize<'de, M: ValueEnum, D: Deserializer<'de>>(d: D) -> Result<M, D::Error> {
        let s = String::deserialize(d)?;
        parse(&s).ok_or_else(|| serde::de::Error::custom(format!("no method '{s}' ({})", names::<M>())))
    }
}

/// `#[serde(with = "crate::choice::by_name_or_none")]`: a method by its name, or `none`.
pub mod by_name_or_none {
    use super::*;

    pub fn serialize<M: ValueEnum, S: Serializer>(m: &Option<M>, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&m.as_ref().map_or_else(|| NONE.to_string(), name))
    }

    pub fn deserialize<'de, M: ValueEnum, D: Deserializer<'de>>(d: D) -> Result<Option<M>, D::Error> {
        none_or(d, |s| parse(s).ok_or_else(|| format!("no method '{s}' ({}, none)", names::<M>())))
    }
}

/// `#[serde(with = "crate::choice::choice_or_none")]`: `auto`, a method by its name, or `none`.
pub mod choice_or_none {
    use super::*;

    pub fn serialize<M: ValueEnum, S: Serializer>(c: &Option<Choice<M>>, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&c.as_ref().map_or_else(|| NONE.to_string(), Choice::to_string))
    }

    pub fn deserialize<'de, M: ValueEnum, D: Deserializer<'de>>(d: D) -> Result<Option<Choice<M>>, D::Error> {
        none_or(d, |s| s.parse().map_err(|_| format!("no method '{s}' (auto, {}, none)", names::<M>())))
    }
}

/// How a task's options spell "no method" (no reference, no comparison).
const NONE: &str = "none";

/// `None` for [`NONE`], else what `parse` makes of the string.
fn none_or<'de, T, D: Deserializer<'de>>(
    d: D,
    parse: impl FnOnce(&str) -> Result<T, String>,
) -> Result<Option<T>, D::Error> {
    let s = String::deserialize(d)?;
    if s == NONE {
        return Ok(None);
    }
    parse(&s).map(Some).map_err(serde::de::Error::custom)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
    enum Way {
        Slow,
        #[value(name = "cpu+gpu")]
        Both,
    }

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    struct Task {
        method: Choice<Way>,
        #[serde(with = "by_name_or_none")]
        reference: Option<Way>,
    }

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    struct Compared {
        #[serde(with = "choice_or_none")]
        reference: Option<Choice<Way>>,
    }

    #[test]
    fn names_come_from_the_value_enum() {
        assert_eq!("auto".parse::<Choice<Way>>(), Ok(Choice::Auto));
        assert_eq!("cpu+gpu".parse::<Choice<Way>>(), Ok(Choice::Fixed(Way::Both)));
        assert_eq!(Choice::Fixed(Way::Both).to_string(), "cpu+gpu");
        assert_eq!("fast".parse::<Choice<Way>>(), Err("no method 'fast' (auto, slow, cpu+gpu)".to_string()));
    }

    #[test]
    fn task_options_round_trip_with_none() {
        let t: Task = serde_json::from_str(r#"{"method":"auto","reference":"none"}"#).unwrap();
        assert_eq!(t, Task { method: Choice::Auto, reference: None });
        let t = Task { method: Choice::Fixed(Way::Slow), reference: Some(Way::Both) };
        let text = serde_json::to_string(&t).unwrap();
        assert_eq!(text, r#"{"method":"slow","reference":"cpu+gpu"}"#);
        assert_eq!(serde_json::from_str::<Task>(&text).unwrap(), t);
        let e = serde_json::from_str::<Task>(r#"{"method":"x","reference":"none"}"#).unwrap_err();
        assert!(e.to_string().starts_with("no method 'x' (auto, slow, cpu+gpu)"), "{e}");
    }

    #[test]
    fn a_choice_or_none_round_trips_each_spelling() {
        for (text, reference) in
            [("auto", Some(Choice::Auto)), ("cpu+gpu", Some(Choice::Fixed(Way::Both))), ("none", None)]
        {
            let json = format!(r#"{{"reference":"{text}"}}"#);
            let c: Compared = serde_json::from_str(&json).unwrap();
            assert_eq!(c, Compared { reference });
            assert_eq!(serde_json::to_string(&c).unwrap(), json);
        }
        let e = serde_json::from_str::<Compared>(r#"{"reference":"x"}"#).unwrap_err();
        assert!(e.to_string().starts_with("no method 'x' (auto, slow, cpu+gpu, none)"), "{e}");
    }
}
