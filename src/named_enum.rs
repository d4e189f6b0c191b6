//! Option enums chosen by name, in case files, rubrics and on the command line.
//!
//! `named_enum!` declares such an enum with each variant's name written once, next to it, and
//! derives every spelling from that one list: `ALL`, `name()`, `FromStr` (whose error lists the
//! valid names), `Display`, serde's `Deserialize`, and the [`NamedEnum`] trait through which the
//! located TOML reader suggests the nearest valid name. A hand-written macro rather than `strum`:
//! strum's `FromStr` error does not say what would be valid, serde would still need the names a
//! second time, and the macro is a screenful with no dependency.

use std::fmt;

/// An enum whose variants are chosen by name. Implemented by `named_enum!`.
pub trait NamedEnum: Copy + 'static {
    /// What one of these is called in messages: "filter", "precision".
    const NOUN: &'static str;
    /// Every variant, in declaration order.
    const ALL: &'static [Self];
    /// Every variant's name, in the order of `ALL`.
    const NAMES: &'static [&'static str];

    /// The name files and flags use.
    fn name(self) -> &'static str;

    fn from_name(name: &str) -> Option<Self> {
        Self::ALL.iter().copied().find(|variant| variant.name() == name)
    }
}

/// Why a string names no variant: `FromStr`'s error for every named enum.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("`{written}` is not a {noun}: {}", Alternatives(valid))]
pub struct UnknownName {
    pub written: String,
    pub noun: &'static str,
    pub valid: &'static [&'static str],
}

impl UnknownName {
    pub fn of<T: NamedEnum>(written: &str) -> UnknownName {
        UnknownName {
            written: written.to_owned(),
            noun: T::NOUN,
            valid: T::NAMES,
        }
    }
}

/// "a", "a or b", "a, b or c".
struct Alternatives(&'static [&'static str]);

impl fmt::Display for Alternatives {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            [] => f.write_str("(none)"),
            [only] => f.write_str(only),
            [init @ .., last] => write!(f, "{} or {last}", init.join(", ")),
        }
    }
}

/// Declares a fieldless enum whose variants are chosen by name:
///
/// ```ignore
/// named_enum! {
///     /// How each output pixel is reconstructed from samples.
///     #[derive(Default)]
///     pub enum Filter: "filter" {
///         #[default]
///         None = "none",
///         Gaussian = "gaussian",
///     }
/// }
/// ```
///
/// The string after the enum's name is its noun in messages. The enum derives `Clone, Copy,
/// Debug, PartialEq, Eq` besides what it asks for, and gets `ALL` (an array, in declaration
/// order), `const fn name`, [`NamedEnum`], `FromStr` (exact names; the error is
/// [`UnknownName`]), `Display` (the name) and `Deserialize` from a string, with serde's own
/// "unknown variant" message.
macro_rules! named_enum {
    (
        $(#[$meta:meta])*
        $vis:vis enum $Enum:ident: $noun:literal {
            $( $(#[$variant_meta:meta])* $Variant:ident = $name:literal ),+ $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        $vis enum $Enum {
            $( $(#[$variant_meta])* $Variant ),+
        }

        impl $Enum {
            /// Every variant, in declaration order.
            pub const ALL: [$Enum; [$($name),+].len()] = [$($Enum::$Variant),+];

            /// The name files and flags use.
            pub const fn name(self) -> &'static str {
                match self {
                    $($Enum::$Variant => $name),+
                }
            }
        }

        impl $crate::named_enum::NamedEnum for $Enum {
            const NOUN: &'static str = $noun;
            const ALL: &'static [$Enum] = &$Enum::ALL;
            const NAMES: &'static [&'static str] = &[$($name),+];

            fn name(self) -> &'static str {
                $Enum::name(self)
            }
        }

        impl ::std::str::FromStr for $Enum {
            type Err = $crate::named_enum::UnknownName;

            fn from_str(text: &str) -> ::std::result::Result<$Enum, Self::Err> {
                <$Enum as $crate::named_enum::NamedEnum>::from_name(text)
                    .ok_or_else(|| $crate::named_enum::UnknownName::of::<$Enum>(text))
            }
        }

        impl ::std::fmt::Display for $Enum {
            fn fmt(&self, f: &mut ::std::fmt::Formatter<'_>) -> ::std::fmt::Result {
                f.write_str(self.name())
            }
        }

        impl<'de> ::serde::Deserialize<'de> for $Enum {
            fn deserialize<D: ::serde::Deserializer<'de>>(deserializer: D) -> ::std::result::Result<$Enum, D::Error> {
                $crate::named_enum::deserialize(deserializer)
            }
        }
    };
}

pub(crate) use named_enum;

/// The body of every named enum's `Deserialize`: a string naming a variant.
pub fn deserialize<'de, T: NamedEnum, D: serde::Deserializer<'de>>(deserializer: D) -> Result<T, D::Error> {
    struct Visitor<T>(std::marker::PhantomData<T>);

    impl<T: NamedEnum> serde::de::Visitor<'_> for Visitor<T> {
        type Value = T;

        fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            write!(f, "the name of a {}", T::NOUN)
        }

        fn visit_str<E: serde::de::Error>(self, name: &str) -> Result<T, E> {
            T::from_name(name).ok_or_else(|| E::unknown_variant(name, T::NAMES))
        }
    }

    deserializer.deserialize_str(Visitor(std::marker::PhantomData))
}

#[cfg(test)]
mod tests {
    use super::*;

    named_enum! {
        /// Three, to see the list punctuated.
        #[derive(Default)]
        enum Fruit: "fruit" {
            #[default]
            Apple = "apple",
            Blood = "blood-orange",
            Pear = "pear",
        }
    }

    #[test]
    fn one_list_gives_every_spelling() {
        assert_eq!(Fruit::ALL, [Fruit::Apple, Fruit::Blood, Fruit::Pear]);
        assert_eq!(Fruit::ALL.map(Fruit::name), ["apple", "blood-orange", "pear"]);
        assert_eq!(<Fruit as NamedEnum>::NAMES, ["apple", "blood-orange", "pear"]);
        assert_eq!("blood-orange".parse(), Ok(Fruit::Blood));
        assert_eq!(Fruit::Pear.to_string(), "pear");
        assert_eq!(Fruit::default(), Fruit::Apple);
    }

    #[test]
    fn unknown_names_list_the_valid_ones() {
        let error = "Apple".parse::<Fruit>().unwrap_err();
        assert_eq!(error.to_string(), "`Apple` is not a fruit: apple, blood-orange or pear");
        assert_eq!(Alternatives(&["none", "gaussian"]).to_string(), "none or gaussian");
        assert_eq!(Alternatives(&["f32"]).to_string(), "f32");
    }

    #[test]
    fn serde_reads_names_and_words_its_own_error() {
        #[derive(serde::Deserialize, Debug)]
        struct Holder {
            fruit: Fruit,
        }
        let holder: Holder = toml::from_str("fruit = \"pear\"").unwrap();
        assert_eq!(holder.fruit, Fruit::Pear);
        let error = toml::from_str::<Holder>("fruit = \"plum\"").unwrap_err();
        assert!(
            error
                .message()
                .contains("unknown variant `plum`, expected one of `apple`, `blood-orange`, `pear`"),
            "{error}"
        );
    }
}
