//! A picture of colour swatches in labelled blocks: one block per patch, one row per method,
//! one column per bounce count, each swatch with a line of text under it. It knows nothing of
//! simulation; `simulate --image` fills it.

use crate::font::FAMILY;
use crate::picture::DrawResult;
use plotters::coord::Shift;
use plotters::prelude::*;
use serde::Serialize;

/// One block: a title, the column labels, and rows of swatches.
#[derive(Clone)]
pub struct Block {
    /// Above the block.
    pub title: String,
    /// Above each column.
    pub columns: Vec<String>,
    /// The rows of swatches.
    pub rows: Vec<Row>,
}

/// One labelled row of swatches.
#[derive(Clone)]
pub struct Row {
    /// Left of the row.
    pub label: String,
    /// Its swatches, one per column.
    pub cells: Vec<Cell>,
}

/// One swatch.
#[derive(Clone)]
pub struct Cell {
    /// Display sRGB (encoded), each in [0, 1].
    pub srgb: [f64; 3],
    /// Written under the swatch.
    pub text: String,
}

/// Where a swatch landed, in pixels: block, row and column indices and its rectangle.
#[derive(Debug, Clone, Serialize)]
pub struct Placed {
    /// Index of its block.
    pub block: usize,
    /// Index of its row in the block.
    pub row: usize,
    /// Index of its column.
    pub column: usize,
    /// Left edge, pixels.
    pub x: u32,
    /// Top edge, pixels.
    pub y: u32,
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
}

const MARGIN: u32 = 12;
const LABEL_WIDTH: u32 = 130;
const COLUMN: u32 = 84;
const SWATCH: (u32, u32) = (76, 48);
const ROW: u32 = 72;
const TITLE: u32 = 28;
const HEADER: u32 = 20;
const GAP: u32 = 14;

/// The picture's size and every swatch's place, before drawing.
pub fn layout(blocks: &[Block]) -> ((u32, u32), Vec<Placed>) {
    let columns = blocks.iter().map(|b| b.columns.len()).max().unwrap_or(0) as u32;
    let width = (2 * MARGIN + LABEL_WIDTH + columns * COLUMN).max(520);
    let mut y = MARGIN;
    let mut placed = Vec::new();
    for (b, block) in blocks.iter().enumerate() {
        y += TITLE + HEADER;
        for (r, row) in block.rows.iter().enumerate() {
            for c in 0..row.cells.len() {
                placed.push(Placed {
                    block: b,
                    row: r,
                    column: c,
                    x: MARGIN + LABEL_WIDTH + c as u32 * COLUMN,
                    y,
                    width: SWATCH.0,
                    height: SWATCH.1,
                });
            }
            y += ROW;
        }
        y += GAP;
    }
    ((width, y + MARGIN - GAP), placed)
}

/// Draws the blocks where [`layout`] placed them.
pub fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, blocks: &[Block]) -> DrawResult<DB> {
    let (_, placed) = layout(blocks);
    root.fill(&WHITE)?;
    let text = |size: f64, colour: RGBColor| (FAMILY, size).into_font().color(&colour);
    let mut y = MARGIN as i32;
    let mut swatches = placed.iter();
    for block in blocks {
        root.draw(&Text::new(
            block.title.clone(),
            (MARGIN as i32, y + 4),
            text(16.0, BLACK),
        ))?;
        y += TITLE as i32;
        for (c, label) in block.columns.iter().enumerate() {
            let x = (MARGIN + LABEL_WIDTH + c as u32 * COLUMN) as i32;
            root.draw(&Text::new(label.clone(), (x + 2, y), text(13.0, BLACK)))?;
        }
        y += HEADER as i32;
        for row in &block.rows {
            root.draw(&Text::new(
                row.label.clone(),
                (MARGIN as i32, y + SWATCH.1 as i32 / 2 - 7),
                text(13.0, BLACK),
            ))?;
            for cell in &row.cells {
                let p = swatches.next().expect("layout places every cell");
                let [r, g, b] = cell.srgb.map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8);
                let (x0, y0) = (p.x as i32, p.y as i32);
                let (x1, y1) = (x0 + p.width as i32 - 1, y0 + p.height as i32 - 1);
                root.draw(&Rectangle::new(
                    [(x0, y0), (x1, y1)],
                    RGBColor(r, g, b).filled(),
                ))?;
                // A thin grey frame, so white and black swatches keep their edges.
                root.draw(&Rectangle::new(
                    [(x0 - 1, y0 - 1), (x1 + 1, y1 + 1)],
                    RGBColor(160, 160, 160),
                ))?;
                root.draw(&Text::new(
                    cell.text.clone(),
                    (x0, y1 + 4),
                    text(12.0, RGBColor(40, 40, 40)),
                ))?;
            }
            y += ROW as i32;
        }
        y += GAP as i32;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn blocks(rows: usize, columns: usize) -> Vec<Block> {
        let cell = |k: usize| Cell {
            srgb: [k as f64 / 10.0, 0.5, 1.0],
            text: format!("{k}"),
        };
        vec![
            Block {
                title: "a".into(),
                columns: (0..columns).map(|c| c.to_string()).collect(),
                rows: (0..rows)
                    .map(|r| Row {
                        label: format!("row {r}"),
                        cells: (0..columns).map(cell).collect(),
                    })
                    .collect(),
            };
            2
        ]
    }

    #[test]
    fn swatches_fit_and_do_not_overlap() {
        let b = blocks(4, 9);
        let ((w, h), placed) = layout(&b);
        assert_eq!(placed.len(), 2 * 4 * 9);
        for (i, p) in placed.iter().enumerate() {
            assert!(p.x + p.width <= w && p.y + p.height + 16 <= h, "{p:?}");
            for q in &placed[i + 1..] {
                let apart = p.x + p.width <= q.x
                    || q.x + q.width <= p.x
                    || p.y + p.height <= q.y
                    || q.y + q.height <= p.y;
                assert!(apart, "{p:?} {q:?}");
            }
        }
    }
}
