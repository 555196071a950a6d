//! [`enum_names!`](crate::enum_names): the names of a small fieldless enum, written once.

/// Gives a fieldless enum its names, from one table of `Variant => "name"` (with
/// `| "alias"`es accepted when read): `name()` (the name on the command line, in files and in
/// JSON), `Display` (that name) and `from_name` (the value of a name or alias, any case). Each
/// type keeps its own `ALL` and `FromStr`, whose error messages differ.
///
/// ```
/// #[derive(Debug, Clone, Copy, PartialEq)]
/// enum Fill {
///     Air,
///     Argon,
/// }
/// glassdb_io::enum_names!(Fill { Air => "air", Argon => "argon" | "ar" });
/// assert_eq!(Fill::Argon.to_string(), "argon");
/// assert_eq!(Fill::from_name("AIR"), Some(Fill::Air));
/// assert_eq!(Fill::from_name("Ar"), Some(Fill::Argon));
/// assert_eq!(Fill::from_name("xenon"), None);
/// ```
#[macro_export]
macro_rules! enum_names {
    ($ty:ident { $($variant:ident => $name:literal $(| $alias:literal)*),+ $(,)? }) => {
        impl $ty {
            /// The name used on the command line, in files and in JSON.
            pub fn name(self) -> &'static str {
                match self {
                    $($ty::$variant => $name),+
                }
            }

            /// The value whose [`name`](Self::name) (or an alias of it) is `s`, any case.
            pub fn from_name(s: &str) -> Option<Self> {
                $(if s.eq_ignore_ascii_case($name) $(|| s.eq_ignore_ascii_case($alias))* {
                    return Some($ty::$variant);
                })+
                None
            }
        }

        impl ::std::fmt::Display for $ty {
            fn fmt(&self, f: &mut ::std::fmt::Formatter<'_>) -> ::std::fmt::Result {
                f.write_str(self.name())
            }
        }
    };
}
