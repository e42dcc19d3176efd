//! hd-io
