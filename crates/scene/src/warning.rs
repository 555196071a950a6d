//! Non-fatal remarks about a scene: the input was usable, but the user should know what was
//! assumed. Each names the file and, where there is one, the line (`scene.obj:LINE: …`); the
//! binary prints them as `warning: …`.

use std::fmt;
use std::path::PathBuf;

/// One remark about a loaded scene.
#[derive(Debug, Clone, PartialEq)]
pub enum SceneWarning {
    /// An `mtllib` names a file that does not exist; the `usemtl` names are still used.
    MissingMaterialLibrary {
        /// The OBJ.
        obj: PathBuf,
        /// The `mtllib` line.
        line: usize,
        /// The library's path.
        library: PathBuf,
    },
    /// A `usemtl` name that no (present) material library defines.
    UndefinedMaterial {
        /// The OBJ.
        obj: PathBuf,
        /// The first `usemtl` line naming it.
        line: usize,
        /// The material.
        name: String,
    },
    /// A polygon that could not be ear-clipped in its plane and was fan-triangulated instead.
    PolygonFanned {
        /// The OBJ.
        obj: PathBuf,
        /// The face's line.
        line: usize,
        /// Its corners.
        vertices: usize,
        /// Why it could not be ear-clipped.
        reason: FanReason,
    },
    /// More fanned polygons than are listed one by one.
    MorePolygonsFanned {
        /// The OBJ.
        obj: PathBuf,
        /// How many more.
        count: usize,
    },
}

/// Why a polygon was fan-triangulated rather than ear-clipped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FanReason {
    /// A vertex lies `deviation` (scene units) from the polygon's plane, more than the
    /// planarity tolerance allows for a polygon of `size` (its bounding-box diagonal).
    NonPlanar {
        /// The farthest corner's distance from the polygon's plane.
        deviation: f64,
        /// The polygon's size (its bounding-box diagonal).
        size: f64,
    },
    /// The outline encloses no net area although its vertices are not on one line: it
    /// crosses itself with opposite windings (a bow tie).
    ZeroArea,
    /// Two edges of the outline cross; the edges are given by their first corners, 1-based
    /// positions in the face as written (edge k runs from corner k to the next corner).
    SelfIntersecting {
        /// The two edges that cross (indices of their first corners).
        edges: [usize; 2],
    },
    /// The outline overlaps or touches itself so that no ear could be cut.
    NoEar,
    /// Too many vertices to ear-clip (quadratic cost); `max` is the limit.
    TooManyVertices {
        /// The most corners clipped.
        max: usize,
    },
}

impl fmt::Display for FanReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            FanReason::NonPlanar { deviation, size } => write!(
                f,
                "is not planar (a vertex lies {deviation:.3e} from its plane, {:.2}% of its size)",
                100.0 * deviation / size
            ),
            FanReason::ZeroArea => write!(
                f,
                "encloses no area (its outline crosses itself with opposite windings)"
            ),
            FanReason::SelfIntersecting { edges: [a, b] } => {
                write!(
                    f,
                    "crosses itself (its edges from corners {a} and {b} cross)"
                )
            }
            FanReason::NoEar => write!(
                f,
                "overlaps or touches itself, so it could not be cut into triangles inside it"
            ),
            FanReason::TooManyVertices { max } => {
                write!(f, "has more than {max} vertices, too many to ear-clip")
            }
        }
    }
}

impl fmt::Display for SceneWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SceneWarning::MissingMaterialLibrary { obj, line, library } => write!(
                f,
                "{}:{line}: material library {} not found (material names still used)",
                obj.display(),
                library.display()
            ),
            SceneWarning::UndefinedMaterial { obj, line, name } => write!(
                f,
                "{}:{line}: material {name:?} is used but defined in no material library",
                obj.display()
            ),
            SceneWarning::PolygonFanned {
                obj,
                line,
                vertices,
                reason,
            } => write!(
                f,
                "{}:{line}: polygon of {vertices} vertices {reason}; fan-triangulated instead \
                 (its triangles may cover area outside it)",
                obj.display()
            ),
            SceneWarning::MorePolygonsFanned { obj, count } => write!(
                f,
                "{}: {count} more polygon{} fan-triangulated (not listed)",
                obj.display(),
                if *count == 1 { "" } else { "s" }
            ),
        }
    }
}
