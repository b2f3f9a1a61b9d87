//! Tests of the `app` layer's modules.

mod cli;
mod config;
mod figures;
mod fnv;
mod report_display;
mod report_gwyddion;
mod report_heatmap;
mod report_output;
mod report_part;
mod report_plot;
mod report_records;
mod units;
