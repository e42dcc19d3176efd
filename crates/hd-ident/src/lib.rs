//! hd-ident
