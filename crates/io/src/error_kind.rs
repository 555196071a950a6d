//! The class every glassdb error belongs to: what a user can do about it. Each library's error
//! type says its class through a `kind()` method; the binaries choose exit codes and hints by
//! it, the viewer its HTTP status, a farm report its `kind` field.

/// What a user can do about a failure (the taxonomy of exrs and image-rs: invalid,
/// unsupported, limits, I/O, and glassdb's own bugs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ErrorKind {
    /// The input is not well formed (corrupt, truncated, contradictory, out of range), or an
    /// option asks for something impossible: fix the input or the option.
    Invalid,
    /// A well-formed input using a feature glassdb does not read or write (deep data,
    /// subsampled channels, another file format, a colour space it does not know): convert it.
    Unsupported,
    /// Larger than a configured limit (pixels, bytes, memory): raise the limit or shrink it.
    Limits,
    /// Reading or writing a file failed (missing, permission denied, disk full).
    Io,
    /// glassdb or a library it uses failed internally (a caught panic): a bug, not a property
    /// of the input.
    Internal,
}

impl ErrorKind {
    /// Every kind, in the order above.
    pub const ALL: [ErrorKind; 5] = [
        ErrorKind::Invalid,
        ErrorKind::Unsupported,
        ErrorKind::Limits,
        ErrorKind::Io,
        ErrorKind::Internal,
    ];
}

crate::enum_names!(ErrorKind {
    Invalid => "invalid",
    Unsupported => "unsupported",
    Limits => "limits",
    Io => "io",
    Internal => "internal",
});

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_have_distinct_names() {
        let names: std::collections::BTreeSet<&str> =
            ErrorKind::ALL.iter().map(|k| k.name()).collect();
        assert_eq!(names.len(), ErrorKind::ALL.len());
        assert_eq!(ErrorKind::Limits.to_string(), "limits");
    }
}
