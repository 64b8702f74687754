//! Files facette writes and reads back: [`atomic_file`], the one atomic writer every
//! output goes through, and [`framed`], the one binary container (magic, version, length,
//! CRC-32) of facette's own binary formats. Lowest layer of the workspace's I/O: it
//! depends on nothing else of facette, so that bsdf, render, lab and the command line all
//! use it.

pub mod atomic_file;
pub mod framed;
