//! Tables read by lane code: each cell holds the four numbers one interpolation step needs
//! (two node values and their slopes, for cubic Hermite), stored once in f64 for the lab's
//! instantiation and once in f32 for the renderer's lanes, so that a lookup is one load of
//! four adjacent numbers per lane ([`Real::gather4`](super::Real::gather4)) instead of four
//! index computations and four scattered loads.

/// Four numbers per cell, in both precisions.
#[derive(Clone, Debug)]
pub struct CellTable {
    wide: Vec<[f64; 4]>,
    narrow: Vec<[f32; 4]>,
}

impl CellTable {
    pub fn new(cells: Vec<[f64; 4]>) -> Self {
        let narrow = cells.iter().map(|c| c.map(|v| v as f32)).collect();
        CellTable {
            wide: cells,
            narrow,
        }
    }

    /// The cells of a table of `(value, slope)` nodes: cell k holds nodes k and k + 1.
    pub fn from_nodes(nodes: &[[f64; 2]]) -> Self {
        Self::new(
            nodes
                .windows(2)
                .map(|w| [w[0][0], w[0][1], w[1][0], w[1][1]])
                .collect(),
        )
    }

    pub fn len(&self) -> usize {
        self.wide.len()
    }

    pub fn is_empty(&self) -> bool {
        self.wide.is_empty()
    }

    #[inline(always)]
    pub fn f64_cells(&self) -> &[[f64; 4]] {
        &self.wide
    }

    #[inline(always)]
    pub fn f32_cells(&self) -> &[[f32; 4]] {
        &self.narrow
    }
}
