//! hd-plot
