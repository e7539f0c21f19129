//! `named_enum!`: an enum of named options with `name()`, `ALL`, `FromStr` (an unknown name
//! lists the valid ones), `Display`, [`NamedEnum`] and (feature `serde`) `Serialize` as the
//! name, shared by the pass's settings, the stats' typed fields, and the renderer's options
//! (the other crates of the workspace declare theirs with the same macro).

/// An enum of named options: every variant has a fixed name, used in files, reports and on
/// command lines; `FromStr` takes the name back. Generic code (a command line's value
/// parser, a config file reader) lists and parses any of them through this trait.
pub trait NamedEnum: Copy + std::str::FromStr<Err = crate::Error> + 'static {
    /// Every variant, in declaration order.
    const ALL: &'static [Self];
    /// The variant's name.
    fn name(self) -> &'static str;
}

/// Declares a `Copy` enum whose variants have string names (see the module docs). The enums
/// are exhaustive: a host matches every option, and a new option is a breaking change.
#[doc(hidden)]
#[macro_export]
macro_rules! named_enum {
    ($(#[$m:meta])* $name:ident, $what:literal, { $($(#[$vm:meta])* $variant:ident => $s:literal),+ $(,)? }) => {
        $(#[$m])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
        pub enum $name {
            $($(#[$vm])* $variant),+
        }

        impl $name {
            /// Every variant, in declaration order.
            pub const ALL: &'static [$name] = &[$($name::$variant),+];
            /// The variant's name on the command line and in reports.
            pub fn name(self) -> &'static str {
                match self {
                    $($name::$variant => $s),+
                }
            }
        }

        impl $crate::NamedEnum for $name {
            const ALL: &'static [$name] = $name::ALL;
            fn name(self) -> &'static str {
                $name::name(self)
            }
        }

        impl std::str::FromStr for $name {
            type Err = $crate::Error;
            fn from_str(s: &str) -> $crate::Result<Self> {
                Self::ALL.iter().copied().find(|v| v.name() == s).ok_or_else(|| $crate::Error::UnknownName {
                    what: $what,
                    name: s.into(),
                    expected: Self::ALL.iter().map(|v| v.name()).collect::<Vec<_>>().join(", "),
                })
            }
        }

        $crate::__named_enum_serde!($name);

        impl std::fmt::Display for $name {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.name())
            }
        }
    };
}

/// `Serialize` as the name, with the engine's `serde` feature (decided here, in the engine,
/// whichever crate declares the enum).
#[cfg(feature = "serde")]
#[doc(hidden)]
#[macro_export]
macro_rules! __named_enum_serde {
    ($name:ident) => {
        impl $crate::__private::serde::Serialize for $name {
            fn serialize<S: $crate::__private::serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
                s.serialize_str(self.name())
            }
        }
    };
}

/// Without the `serde` feature: nothing.
#[cfg(not(feature = "serde"))]
#[doc(hidden)]
#[macro_export]
macro_rules! __named_enum_serde {
    ($name:ident) => {};
}

pub(crate) use named_enum;
