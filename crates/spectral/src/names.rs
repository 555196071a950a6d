//! `names!`: the command-line and JSON names of the crate's small enums (name, `ALL`,
//! `Display`, `FromStr` with aliases, any case); `serde_as_name!`: JSON as that name.

macro_rules! names {
    ($ty:ty { $($variant:ident => $name:literal $(| $alias:literal)*),+ $(,)? }) => {
        impl $ty {
            /// The name used on the command line and in JSON.
            pub fn name(self) -> &'static str {
                match self { $(<$ty>::$variant => $name),+ }
            }
            /// Every value, for help texts.
            pub const ALL: &'static [$ty] = &[$(<$ty>::$variant),+];
        }
        impl ::std::fmt::Display for $ty {
            fn fmt(&self, f: &mut ::std::fmt::Formatter<'_>) -> ::std::fmt::Result {
                f.write_str(self.name())
            }
        }
        impl ::std::str::FromStr for $ty {
            type Err = String;
            fn from_str(s: &str) -> Result<Self, String> {
                $(if s.eq_ignore_ascii_case($name) $(|| s.eq_ignore_ascii_case($alias))* {
                    return Ok(<$ty>::$variant);
                })+
                Err(format!("unknown value `{s}`; expected one of: {}", [$($name),+].join(", ")))
            }
        }
    };
}

/// Serialises a type as its `name()` and deserialises it with its `FromStr`.
macro_rules! serde_as_name {
    ($ty:ty) => {
        impl ::serde::Serialize for $ty {
            fn serialize<S: ::serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.serialize_str(self.name())
            }
        }
        impl<'de> ::serde::Deserialize<'de> for $ty {
            fn deserialize<D: ::serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                <String as ::serde::Deserialize>::deserialize(d)?
                    .parse()
                    .map_err(::serde::de::Error::custom)
            }
        }
    };
}
