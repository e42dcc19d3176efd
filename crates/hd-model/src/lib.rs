//! hd-model
