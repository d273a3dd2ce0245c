//! fuzzyvox's native map files: one container (a fixed header, a postcard body, a CRC32) for the
//! fuzzy, log-odds and alpha-cut maps, written atomically so that a crash never leaves a
//! half-written file. The maps' `save`, `load`, `to_bytes` and `from_bytes` are defined here,
//! beside the format they write; [`AnyMap`](crate::map::AnyMap) reads a file of any kind.
//! The maps themselves know nothing of files: this module depends on [`map`](crate::map), never
//! the reverse.
//!
//! Readers take bytes from anywhere, so this module may not index or slice: every access to
//! file bytes is checked (`get`, `split_at_checked`, patterns), and a bad file is an error.
#![cfg_attr(not(test), deny(clippy::indexing_slicing))]

mod any_file;
mod atomic;
mod fuzzy_file;
mod logodds_file;
mod mapfile;
mod stored_blocks;

pub use atomic::{write_atomic, write_atomic_with};
pub use mapfile::{MAGIC, MapHeader, read_checked, read_header};
