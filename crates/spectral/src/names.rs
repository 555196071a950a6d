//! `names!`: the command-line and JSON names of the crate's small enums (`glassdb_io::enum_names!`
//! with `ALL` and a `FromStr` with aliases, any case); `serde_as_name!`: JSON as that name.

macro_rules! names {
    ($ty:ident { $($variant:ident => $name:literal $(| $alias:literal)*),+ $(,)? }) => {
        glassdb_io::enum_names!($ty { $($variant => $name $(| $alias)*),+ });
        impl $ty {
            /// Every value, for help texts.
            pub const ALL: &'static [$ty] = &[$(<$ty>::$variant),+];
        }
        impl ::std::str::FromStr for $ty {
            type Err = String;
            fn from_str(s: &str) -> Result<Self, String> {
                Self::from_name(s).ok_or_else(|| {
                    format!("unknown value `{s}`; expected one of: {}", [$($name),+].join(", "))
                })
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
