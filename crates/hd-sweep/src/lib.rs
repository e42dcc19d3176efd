//! hd-sweep
