//! The `facette` command line end to end, one module per area, in one binary: the
//! workspace links once instead of once per file, and libtest spreads the long tests of
//! every module over the threads.

mod cli;
mod cli_render;
mod cli_tables_and_maps;
mod common;
mod fuzz_readers;
mod fuzz_support;
mod lab;
mod render_mitsuba;
mod robustness;
