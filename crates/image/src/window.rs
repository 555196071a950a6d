//! OpenEXR's coordinate model: every pixel has integer coordinates shared by all images of a
//! frame; a file stores the pixels of its data window, and its display window is the frame the
//! image is meant to fill. A PNG stores its whole frame at (0, 0).

/// A rectangle of pixels in an image's coordinates: the top-left pixel and the size.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct PixelWindow {
    /// Column of its top-left pixel.
    pub x: i32,
    /// Row of its top-left pixel.
    pub y: i32,
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
}

impl PixelWindow {
    /// A window of `width × height` pixels at the origin (a PNG's frame).
    pub fn at_origin(width: usize, height: usize) -> PixelWindow {
        PixelWindow {
            x: 0,
            y: 0,
            width,
            height,
        }
    }

    /// One past the rightmost column.
    pub fn end_x(&self) -> i64 {
        i64::from(self.x) + self.width as i64
    }

    /// One past the bottom row.
    pub fn end_y(&self) -> i64 {
        i64::from(self.y) + self.height as i64
    }

    /// Number of pixels.
    pub fn pixel_count(&self) -> u64 {
        (self.width as u64).saturating_mul(self.height as u64)
    }

    /// Whether pixel (x, y) lies inside.
    pub fn contains(&self, x: i64, y: i64) -> bool {
        x >= i64::from(self.x) && x < self.end_x() && y >= i64::from(self.y) && y < self.end_y()
    }

    /// Whether every pixel of `other` lies inside.
    pub fn contains_window(&self, other: &PixelWindow) -> bool {
        other.width == 0
            || other.height == 0
            || (other.x >= self.x
                && other.y >= self.y
                && other.end_x() <= self.end_x()
                && other.end_y() <= self.end_y())
    }

    /// The pixels both windows hold, if any.
    pub fn intersection(&self, other: &PixelWindow) -> Option<PixelWindow> {
        let x0 = self.x.max(other.x);
        let y0 = self.y.max(other.y);
        let x1 = self.end_x().min(other.end_x());
        let y1 = self.end_y().min(other.end_y());
        (x1 > i64::from(x0) && y1 > i64::from(y0)).then(|| PixelWindow {
            x: x0,
            y: y0,
            width: (x1 - i64::from(x0)) as usize,
            height: (y1 - i64::from(y0)) as usize,
        })
    }

    /// Row-major index of pixel (x, y) in a buffer holding this window, if it lies inside.
    pub fn index_of(&self, x: i64, y: i64) -> Option<usize> {
        self.contains(x, y).then(|| {
            (y - i64::from(self.y)) as usize * self.width + (x - i64::from(self.x)) as usize
        })
    }
}

impl std::fmt::Display for PixelWindow {
    /// OpenEXR's inclusive form, `(xMin, yMin)–(xMax, yMax)`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "({}, {})–({}, {})",
            self.x,
            self.y,
            self.end_x() - 1,
            self.end_y() - 1
        )
    }
}

/// Where an image's pixels lie: its data window (the pixels stored) inside its display window
/// (the frame). For a PNG both are its size at (0, 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ImageWindows {
    /// The pixels stored.
    pub data: PixelWindow,
    /// The frame they belong to.
    pub display: PixelWindow,
}

impl ImageWindows {
    /// A whole frame of `width × height` at the origin.
    pub fn full_frame(width: usize, height: usize) -> ImageWindows {
        let w = PixelWindow::at_origin(width, height);
        ImageWindows {
            data: w,
            display: w,
        }
    }
}

/// Copies the pixels of `src` (a buffer holding window `from`) into a new buffer holding window
/// `to`; pixels of `to` outside `from` get `fill`.
pub fn place_plane<T: Copy>(src: &[T], from: &PixelWindow, to: &PixelWindow, fill: T) -> Vec<T> {
    if from == to && src.len() == to.width * to.height {
        return src.to_vec();
    }
    let mut out = vec![fill; to.width * to.height];
    if let Some(common) = from.intersection(to) {
        for y in common.y..(common.end_y() as i32) {
            let (y, cx) = (i64::from(y), i64::from(common.x));
            let (Some(s), Some(d)) = (from.index_of(cx, y), to.index_of(cx, y)) else {
                continue;
            };
            if let (Some(src_row), Some(dst_row)) = (
                src.get(s..s + common.width),
                out.get_mut(d..d + common.width),
            ) {
                dst_row.copy_from_slice(src_row);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn intersection_and_placement_follow_coordinates() {
        let a = PixelWindow {
            x: -1,
            y: 2,
            width: 3,
            height: 2,
        };
        let b = PixelWindow::at_origin(4, 4);
        let i = a.intersection(&b).unwrap();
        assert_eq!(
            i,
            PixelWindow {
                x: 0,
                y: 2,
                width: 2,
                height: 2
            }
        );
        // a holds (-1,2) (0,2) (1,2) / (-1,3) (0,3) (1,3) as 1..=6.
        let placed = place_plane(&[1, 2, 3, 4, 5, 6], &a, &b, 0);
        assert_eq!(placed, vec![0, 0, 0, 0, 0, 0, 0, 0, 2, 3, 0, 0, 5, 6, 0, 0]);
        assert!(a.intersection(&PixelWindow::at_origin(0, 0)).is_none());
        assert_eq!(a.to_string(), "(-1, 2)–(1, 3)");
        assert!(b.contains_window(&i) && !b.contains_window(&a));
    }
}
