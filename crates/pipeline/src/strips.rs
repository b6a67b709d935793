//! The unit read from the input: a strip, one row of a level's blocks ([`Strip`]).

use specconv_exr::{Block, SpectralFile};

/// One row of blocks: the unit read from the input.
pub(crate) struct Strip {
    pub(crate) level: usize,
    pub(crate) y: usize,
    pub(crate) height: usize,
    pub(crate) blocks: Vec<Block>,
}

/// Groups the file's blocks into rows (they come level by level, row by row).
pub(crate) fn strips(file: &SpectralFile) -> Vec<Strip> {
    let mut out: Vec<Strip> = Vec::new();
    for b in file.blocks() {
        match out.last_mut() {
            Some(s) if s.level == b.level && s.y == b.y => s.blocks.push(b),
            _ => out.push(Strip {
                level: b.level,
                y: b.y,
                height: b.height,
                blocks: vec![b],
            }),
        }
    }
    out
}
