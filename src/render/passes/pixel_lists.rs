//! The pixel lists the relight pass runs over: every covered pixel, and the pixels restarted
//! alone ([`crate::render::Renderer::restart_pixels`]), each compacted and row-major, so that no
//! invocation idles on background and a band of rows is one contiguous range. Each list is an
//! `R32_UINT` image of the g-buffer's size read as a flat array (entry `i` is texel
//! `(i % width, i / width)`), which holds any list and is not bound by the storage-buffer range.

use crate::gbuffer::GBuffer;
use crate::gpu::{Buffer, Context, Image};
use crate::Result;
use ash::vk;

/// A pixel as the lists hold it: `x | y << 16` (sides are at most 32768).
pub fn pack(x: u32, y: u32) -> u32 {
    x | y << 16
}

/// A list of pixels on the host, with where each row's entries start.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RowList {
    /// Packed pixels ([`pack`]), row-major.
    pub pixels: Vec<u32>,
    /// Where row `y`'s entries start; `rows[height]` is the end.
    pub rows: Vec<u32>,
}

impl RowList {
    /// The list of `indices` (`y * width + x`, ascending) of a `width` × `height` image.
    pub fn from_indices(width: u32, height: u32, indices: impl IntoIterator<Item = u32>) -> RowList {
        let mut list = RowList { pixels: Vec::new(), rows: vec![0; height as usize + 1] };
        for index in indices {
            let (x, y) = (index % width, index / width);
            list.pixels.push(pack(x, y));
            list.rows[y as usize + 1] += 1;
        }
        for y in 0..height as usize {
            list.rows[y + 1] += list.rows[y];
        }
        list
    }

    /// The entries of rows `first_row..end_row`.
    pub fn range(&self, first_row: u32, end_row: u32) -> (u32, u32) {
        (self.rows[first_row as usize], self.rows[end_row as usize])
    }

    /// How many entries row `y` has.
    pub fn row_len(&self, y: u32) -> u32 {
        self.rows[y as usize + 1] - self.rows[y as usize]
    }
}

/// The lists on the GPU, with the per-row counts of pixels still active under a noise threshold.
pub struct PixelLists {
    /// Every pixel with coverage > 0.
    pub covered: RowList,
    /// Whether each pixel (`y * width + x`) is covered.
    pub covered_mask: Vec<bool>,
    /// [`Self::covered`] on the GPU.
    pub covered_image: Image,
    /// The restarted pixels on the GPU; rewritten by [`Self::upload_restarted`].
    pub restarted_image: Image,
    /// A host-visible `uint` per row: the pixels the last pass over the row left active.
    pub active: Buffer,
    /// Host-visible: where each row's entries start in the covered list (`height + 1`), then
    /// how many pixels of each row the active list a dispatch reads holds (`height`).
    pub active_rows: Buffer,
}

impl PixelLists {
    /// The lists of a g-buffer: built once, on the host, from its coverage.
    pub fn new(ctx: &Context, gbuffer: &GBuffer) -> Result<PixelLists> {
        let (width, height) = (gbuffer.width, gbuffer.height);
        let covered_mask: Vec<bool> = gbuffer.coverage.iter().map(|&a| a > 0.0).collect();
        let indices = covered_mask.iter().enumerate().filter(|(_, &c)| c).map(|(i, _)| i as u32);
        let covered = RowList::from_indices(width, height, indices);
        let covered_image = list_image(ctx, width, height)?;
        upload_list(ctx, &covered_image, &covered.pixels)?;
        let restarted_image = list_image(ctx, width, height)?;
        let active = Buffer::staging(ctx, height as u64 * 4)?;
        let mut active_rows = Buffer::staging(ctx, (2 * height as u64 + 1) * 4)?;
        active_rows.bytes_mut()[..covered.rows.len() * 4].copy_from_slice(bytemuck::cast_slice(&covered.rows));
        Ok(PixelLists { covered, covered_mask, covered_image, restarted_image, active, active_rows })
    }

    /// Writes `list` as the restarted pixels.
    pub fn upload_restarted(&self, ctx: &Context, list: &RowList) -> Result<()> {
        upload_list(ctx, &self.restarted_image, &list.pixels)
    }

    /// Sets the active counts of rows `first_row..end_row` to zero before a pass counts them.
    pub fn clear_active(&mut self, first_row: u32, end_row: u32) {
        let bytes = &mut self.active.bytes_mut()[first_row as usize * 4..end_row as usize * 4];
        bytes.fill(0);
    }

    /// Sets how many pixels of rows `first_row..end_row` the active list to be read holds.
    pub fn set_entering(&mut self, first_row: u32, end_row: u32, counts: &[u32]) {
        let height = self.covered.rows.len() - 1;
        let at = (height + 1 + first_row as usize) * 4;
        let rows = &counts[first_row as usize..end_row as usize];
        self.active_rows.bytes_mut()[at..at + rows.len() * 4].copy_from_slice(bytemuck::cast_slice(rows));
    }

    /// The active count of row `y`, as the last pass over it left it.
    pub fn active(&self, y: u32) -> u32 {
        bytemuck::pod_read_unaligned(&self.active.bytes()[y as usize * 4..y as usize * 4 + 4])
    }
}

/// An image that holds a list of up to `width` × `height` pixels.
pub fn list_image(ctx: &Context, width: u32, height: u32) -> Result<Image> {
    Image::new(ctx, vk::Format::R32_UINT, width, height, 1, false)
}

/// Writes `pixels` (packed, at most the image's texels) into the list image `image`, straight
/// into the memory its upload copies from, zeros after them.
pub fn upload_list(ctx: &Context, image: &Image, pixels: &[u32]) -> Result<()> {
    image.upload_with(ctx, |bytes| {
        let (list, rest) = bytes.split_at_mut(std::mem::size_of_val(pixels));
        list.copy_from_slice(bytemuck::cast_slice(pixels));
        rest.fill(0);
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_band_of_rows_is_one_range_of_the_list() {
        // 4 × 3: row 0 has pixels 1 and 3, row 1 none, row 2 pixel 0.
        let list = RowList::from_indices(4, 3, [1, 3, 8]);
        assert_eq!(list.pixels, vec![pack(1, 0), pack(3, 0), pack(0, 2)]);
        assert_eq!(list.rows, vec![0, 2, 2, 3]);
        assert_eq!(list.range(0, 1), (0, 2));
        assert_eq!(list.range(1, 3), (2, 3));
        assert_eq!((list.row_len(0), list.row_len(1), list.row_len(2)), (2, 0, 1));
    }
}
