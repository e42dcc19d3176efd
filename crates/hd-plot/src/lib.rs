//! Plots (SVG and PNG) for the workbench, drawn with plotters.
