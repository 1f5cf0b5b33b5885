//! Wireframe pictures of triangle meshes, as PNG (raster) or SVG (vector).
//!
//! The picture is the kind used for mesh figures in papers: every triangle is
//! filled with a light, shaded colour and outlined in dark grey, and the
//! triangles are drawn back to front (painter's algorithm, ordered by the
//! depth of their centroids) so that the faces nearer the camera cover the
//! edges behind them. Hidden lines are therefore removed and the shape of the
//! surface reads at a glance. Faces seen from behind (the side their
//! counter-clockwise orientation does not face), which show through holes
//! and past open boundaries, are drawn in a darker, warmer grey.
//!
//! * [`render_png`] rasterises with [`tiny_skia`] and returns the PNG bytes.
//! * [`render_svg`] writes one `<polygon>` per triangle in the same order
//!   (with [`ColorBy::EdgeNormalAngle`], also one `<line>` per edge).
//! * [`render_to_file`] picks the format from the file extension.
//!
//! The camera always looks at the centre of the bounding box of all the
//! vertices, and the bounding sphere about that centre is fitted into the
//! image, leaving [`RenderOptions::margin`] free on every side. Vertices not
//! used by any triangle count too, so a selection of triangles over the same
//! vertex list is framed exactly like the whole mesh.
//!
//! Edges shorter on the picture than a few pixels are faded and, below
//! [`EDGE_HIDDEN_BELOW`], left out (see [`EDGE_FULL_FROM`]): a mesh of a
//! hundred thousand triangles reads by its shading instead of turning black
//! under its edges, and a small mesh keeps all of its edges.
//!
//! Output is deterministic: faces at equal depth are drawn in index order,
//! and the same mesh and options give byte-identical files.
//!
//! Painter's algorithm is exact for the small, well-shaped triangles of a
//! fine mesh; where large triangles interpenetrate or overlap cyclically in
//! depth it can draw the wrong one on top, as any depth-sort renderer does.
//!
//! This module is the binary's (`liemesh render`, `liemesh mesh --png`, `liemesh paper`), not
//! the library's: a program that depends on liemesh does not build tiny-skia, png and svg.

use std::path::{Path, PathBuf};

use svg::node::element::{Group, Line, Polygon, Rectangle};
use svg::Document;
use tiny_skia::{
    Color, FillRule, LineCap, LineJoin, Paint, PathBuilder, Pixmap, Stroke, Transform,
};

use liemesh::Mesh;

/// Largest accepted image width or height, in pixels.
pub const MAX_IMAGE_SIZE: u32 = 16384;

/// Minimum interior angle, in degrees, at the top of the [`ColorBy::MinAngle`]
/// colour ramp (an equilateral triangle).
pub const MIN_ANGLE_RAMP_MAX_DEGREES: f64 = 60.0;

/// Angle between vertex normals, in degrees, at the top of the
/// [`ColorBy::EdgeNormalAngle`] colour ramp; larger angles get the same colour.
pub const EDGE_NORMAL_ANGLE_RAMP_MAX_DEGREES: f64 = 30.0;

/// Edges whose projection is at most this many line widths long (or pixels, for lines up
/// to a pixel wide) are not drawn: the faces' shading shows the surface there.
pub const EDGE_HIDDEN_BELOW: f32 = 2.0;

/// Edges whose projection is at least this many line widths (or pixels) long are drawn in
/// full; between [`EDGE_HIDDEN_BELOW`] and this, their opacity grows with their length.
///
/// Edges of length `L` cover about `3.5 w / L` of a mesh of equilateral faces drawn with
/// lines `w` wide: drawn in full, a mesh of 4-pixel faces would be nearly black. Faded in
/// proportion, the lines darken the faces by at most about a third at any density.
pub const EDGE_FULL_FROM: f32 = 10.0;

/// Opacity steps of faded edges (edges of one colour and opacity are drawn together).
const FADE_STEPS: f32 = 16.0;

/// Where the camera stands and how it projects.
///
/// `direction` points from the centre of the mesh towards the camera (the
/// camera looks back along it, at the centre). `up` is the direction that
/// should appear upwards in the picture; only its component perpendicular to
/// `direction` matters, and if it has none (it is zero or parallel to
/// `direction`) a coordinate axis is used instead. Neither vector needs to be
/// of unit length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum View {
    /// Parallel projection.
    Orthographic {
        /// From the mesh centre towards the camera.
        direction: [f64; 3],
        /// Upwards in the picture.
        up: [f64; 3],
    },
    /// Central projection with the given full opening angle of the view cone.
    ///
    /// The camera is placed at the distance at which the bounding sphere just
    /// fills the cone, so a wider angle means a closer camera and stronger
    /// perspective.
    Perspective {
        /// From the mesh centre towards the camera.
        direction: [f64; 3],
        /// Upwards in the picture.
        up: [f64; 3],
        /// Full opening angle of the view cone in degrees, strictly between 0 and 180.
        fov_degrees: f64,
    },
}

impl Default for View {
    /// An orthographic three-quarter view from about 24° above the `xy`-plane,
    /// with `+z` upwards.
    fn default() -> Self {
        View::Orthographic {
            direction: [2.0, -3.0, 1.6],
            up: [0.0, 0.0, 1.0],
        }
    }
}

/// What, if anything, the colours of the picture encode.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ColorBy {
    /// Light grey faces, edges in [`RenderOptions::edge_color`].
    #[default]
    None,
    /// Each face is coloured by its smallest interior angle (measured in 3D)
    /// on a red–yellow–blue ramp: red at 0°, yellow at 30°, blue at
    /// [`MIN_ANGLE_RAMP_MAX_DEGREES`] (60°). Front faces are shaded lightly
    /// (down to 78 % of the ramp colour when seen edge-on); back faces are
    /// greyed and darker.
    MinAngle,
    /// Each edge is coloured by the angle between the stored vertex normals
    /// ([`Mesh::normals`]) at its two ends, rounded to whole degrees: dark
    /// blue at 0°, purple at 15°, red at
    /// [`EDGE_NORMAL_ANGLE_RAMP_MAX_DEGREES`] (30°) and above. A zero normal
    /// counts as 180°. Faces are plain light grey. Needs one finite normal
    /// per vertex.
    EdgeNormalAngle,
}

/// Settings for [`render_png`], [`render_svg`] and [`render_to_file`].
///
/// Build one with struct-update syntax from [`RenderOptions::default`]:
/// `RenderOptions { width: 400, ..RenderOptions::default() }`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderOptions {
    /// Image width in pixels, 1 to [`MAX_IMAGE_SIZE`]. Default 800.
    pub width: u32,
    /// Image height in pixels, 1 to [`MAX_IMAGE_SIZE`]. Default 800.
    pub height: u32,
    /// Camera placement and projection. Default [`View::default`].
    pub view: View,
    /// Colour coding of faces or edges. Default [`ColorBy::None`].
    pub color_by: ColorBy,
    /// Edge stroke width in pixels; 0 draws no edges (shaded faces only).
    /// Must be finite and not negative. Default 1.0.
    ///
    /// In PNG output, widths up to 1 use tiny-skia's fast hairline
    /// rasteriser (narrower lines are drawn fainter rather than thinner);
    /// wider lines are stroked as outlines, about three times slower for
    /// meshes with many triangles.
    pub line_width: f32,
    /// Background colour as RGBA; alpha 0 gives a transparent background.
    /// Default opaque white.
    pub background: [u8; 4],
    /// Edge colour as RGBA, used unless [`ColorBy::EdgeNormalAngle`] is
    /// chosen. Default opaque dark grey `[30, 30, 30, 255]`.
    pub edge_color: [u8; 4],
    /// Free border on every side, as a fraction of the smaller image
    /// dimension, in `[0, 0.5)`. Default 0.05.
    pub margin: f64,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 800,
            height: 800,
            view: View::default(),
            color_by: ColorBy::None,
            line_width: 1.0,
            background: [255, 255, 255, 255],
            edge_color: [30, 30, 30, 255],
            margin: 0.05,
        }
    }
}

/// Why a mesh could not be rendered or the picture could not be written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RenderError {
    /// The mesh has no triangles.
    #[error("cannot render an empty mesh: it has {vertices} vertices and no triangles")]
    EmptyMesh {
        /// Number of vertices in the mesh.
        vertices: usize,
    },
    /// A vertex coordinate is NaN or infinite.
    #[error(
        "vertex {index} has a non-finite coordinate ({x}, {y}, {z}); every vertex coordinate must be a finite number",
        x = .position[0], y = .position[1], z = .position[2]
    )]
    NonFiniteVertex {
        /// Index of the offending vertex.
        index: usize,
        /// Its position.
        position: [f64; 3],
    },
    /// A vertex normal is NaN or infinite (checked only for [`ColorBy::EdgeNormalAngle`]).
    #[error(
        "normal {index} has a non-finite component ({x}, {y}, {z}); colouring edges by normal angle needs finite normals",
        x = .normal[0], y = .normal[1], z = .normal[2]
    )]
    NonFiniteNormal {
        /// Index of the offending vertex.
        index: usize,
        /// Its normal.
        normal: [f64; 3],
    },
    /// The mesh does not have one normal per vertex (checked only for
    /// [`ColorBy::EdgeNormalAngle`]).
    #[error(
        "colouring edges by normal angle needs one normal per vertex, but the mesh has {normals} normals for {vertices} vertices"
    )]
    MissingNormals {
        /// Number of normals in the mesh.
        normals: usize,
        /// Number of vertices in the mesh.
        vertices: usize,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error(
        "triangle {triangle} refers to vertex {vertex}, but the mesh has only {vertex_count} vertices, so vertex indices must be below {vertex_count}"
    )]
    IndexOutOfRange {
        /// Index of the offending triangle.
        triangle: usize,
        /// The vertex index it contains.
        vertex: u32,
        /// Number of vertices in the mesh.
        vertex_count: usize,
    },
    /// The mesh is so large that its extent overflows `f64`.
    #[error("the mesh is too large to render: its extent overflows a 64-bit float")]
    ExtentOverflow,
    /// Width or height is 0 or larger than [`MAX_IMAGE_SIZE`].
    #[error(
        "image size {width}x{height} is not allowed: width and height must each be between 1 and {max} pixels",
        max = MAX_IMAGE_SIZE
    )]
    BadSize {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
    },
    /// The [`View`] cannot be used.
    #[error("invalid view: {reason}")]
    InvalidView {
        /// What is wrong with it.
        reason: String,
    },
    /// Another field of [`RenderOptions`] is out of range.
    #[error("invalid render option `{name}`: {reason}")]
    InvalidOption {
        /// Name of the field.
        name: &'static str,
        /// What is wrong with it.
        reason: String,
    },
    /// [`render_to_file`] was given a path that does not end in `.png` or `.svg`.
    #[error(
        "cannot tell which image format to write to {}: the file name must end in .png or .svg",
        .path.display()
    )]
    UnsupportedExtension {
        /// The path as given.
        path: PathBuf,
    },
    /// The PNG encoder failed.
    #[error("could not encode the picture as PNG: {message}")]
    PngEncoding {
        /// The encoder's message.
        message: String,
    },
    /// Writing the file failed.
    #[error("could not write the picture to {}: {source}", .path.display())]
    Io {
        /// The path that could not be written.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
}

/// Renders `mesh` to PNG and returns the encoded file contents.
///
/// The image is RGB if the background is opaque and RGBA otherwise, and is
/// compressed for speed rather than size. Faces are filled, and each edge is
/// stroked once, after the fills of both its faces and before anything that
/// lies in front of it, fainter the shorter it is on the picture (see
/// [`EDGE_FULL_FROM`]). Faces are filled without anti-aliasing when opaque
/// edges at least a pixel wide cover their borders (this also avoids faint
/// seams between neighbouring faces), and with it otherwise.
///
/// # Errors
///
/// Any [`RenderError`] except [`RenderError::UnsupportedExtension`] and
/// [`RenderError::Io`]: an empty or malformed mesh, or invalid options.
pub fn render_png(mesh: &Mesh, options: &RenderOptions) -> Result<Vec<u8>, RenderError> {
    let scene = Scene::new(mesh, options)?;
    let pixmap = rasterize(&scene, options, Painter::MAX_BATCH)?;
    encode_png(pixmap, options.background[3] == 255)
}

/// Draws `scene` with batches of at most `max_batch` faces.
fn rasterize(
    scene: &Scene,
    options: &RenderOptions,
    max_batch: usize,
) -> Result<Pixmap, RenderError> {
    let mut pixmap = Pixmap::new(options.width, options.height).ok_or(RenderError::BadSize {
        width: options.width,
        height: options.height,
    })?;
    let [r, g, b, a] = options.background;
    pixmap.fill(Color::from_rgba8(r, g, b, a));

    let draw_edges = options.line_width > 0.0;
    // Anti-aliased fills let a trace of whatever lies below leak through the
    // seams between faces; aliased fills tile exactly. Their jagged borders
    // lie under the edges, so they are used whenever opaque edges at least a
    // pixel wide cover them.
    let edges_cover_borders = draw_edges
        && options.line_width >= 1.0
        && (options.color_by == ColorBy::EdgeNormalAngle || options.edge_color[3] == 255);
    let mut painter = Painter {
        pixmap,
        fill: Paint {
            anti_alias: !edges_cover_borders,
            ..Paint::default()
        },
        line: Paint::default(),
        stroke: Stroke {
            width: options.line_width,
            line_cap: LineCap::Round,
            line_join: LineJoin::Round,
            ..Stroke::default()
        },
        draw_edges,
        max_batch,
        batch: Vec::with_capacity(max_batch),
    };
    // Half the stroke width, plus a pixel for anti-aliasing and rounding.
    let pad = 0.5 * options.line_width + 1.5;
    for face in &scene.faces {
        let [p0, p1, p2] = face.points;
        let bounds = [
            p0[0].min(p1[0]).min(p2[0]) - pad,
            p0[1].min(p1[1]).min(p2[1]) - pad,
            p0[0].max(p1[0]).max(p2[0]) + pad,
            p0[1].max(p1[1]).max(p2[1]) + pad,
        ];
        painter.push(face, bounds);
    }
    painter.flush();
    Ok(painter.pixmap)
}

/// Draws faces for [`render_png`] in drawing order, with the result of
/// filling and stroking each face in turn, but in far fewer tiny-skia calls.
///
/// Consecutive faces are collected into a batch as long as their padded
/// screen bounding boxes are pairwise disjoint. Within such a batch no face
/// can cover any part of another face or its edges, so the order of drawing
/// inside it does not matter: all fills of one colour go into one path, and
/// all edges of one colour into one stroked path. A face that would overlap
/// the batch first flushes it, which keeps back-to-front order between
/// overlapping faces.
struct Painter<'a> {
    pixmap: Pixmap,
    fill: Paint<'static>,
    line: Paint<'static>,
    stroke: Stroke,
    draw_edges: bool,
    /// Largest number of faces in a batch.
    max_batch: usize,
    /// Faces of the current batch with their padded bounds `[x0, y0, x1, y1]`.
    batch: Vec<(&'a Face, [f32; 4])>,
}

impl<'a> Painter<'a> {
    /// Default batch size limit, bounding the quadratic cost of the overlap
    /// tests.
    const MAX_BATCH: usize = 64;

    /// Adds `face`, whose padded screen bounds are `bounds`, flushing the
    /// batch first if the face overlaps it.
    fn push(&mut self, face: &'a Face, bounds: [f32; 4]) {
        let overlaps = |b: &[f32; 4]| {
            bounds[0] <= b[2] && b[0] <= bounds[2] && bounds[1] <= b[3] && b[1] <= bounds[3]
        };
        if self.batch.len() >= self.max_batch || self.batch.iter().any(|(_, b)| overlaps(b)) {
            self.flush();
        }
        self.batch.push((face, bounds));
    }

    /// Draws the batch: fills, then edges, each grouped by colour.
    fn flush(&mut self) {
        let mut faces: Vec<&Face> = self.batch.drain(..).map(|(face, _)| face).collect();
        // Stable sorts: the order within a colour is the drawing order.
        faces.sort_by_key(|face| face.fill);
        for group in faces.chunk_by(|a, b| a.fill == b.fill) {
            let [r, g, b] = group[0].fill;
            self.fill.set_color_rgba8(r, g, b, 255);
            if let Some(path) = path_of(group.iter().map(|face| &face.points[..]), true) {
                let identity = Transform::identity();
                self.pixmap
                    .fill_path(&path, &self.fill, FillRule::Winding, identity, None);
            }
        }
        if !self.draw_edges {
            return;
        }
        let mut edges: Vec<([u8; 4], [[f32; 2]; 2])> =
            faces.iter().flat_map(|face| face.drawn_edges()).collect();
        edges.sort_by_key(|&(color, _)| color);
        for group in edges.chunk_by(|a, b| a.0 == b.0) {
            let [r, g, b, a] = group[0].0;
            self.line.set_color_rgba8(r, g, b, a);
            if let Some(path) = path_of(group.iter().map(|(_, segment)| &segment[..]), false) {
                let identity = Transform::identity();
                self.pixmap
                    .stroke_path(&path, &self.line, &self.stroke, identity, None);
            }
        }
    }
}

/// A tiny-skia path made of the given polylines, each closed if `close`;
/// `None` if there is nothing to draw or a coordinate is not finite.
fn path_of<'p>(
    polylines: impl Iterator<Item = &'p [[f32; 2]]>,
    close: bool,
) -> Option<tiny_skia::Path> {
    let mut builder = PathBuilder::new();
    for points in polylines {
        let Some((first, rest)) = points.split_first() else {
            continue;
        };
        builder.move_to(first[0], first[1]);
        for p in rest {
            builder.line_to(p[0], p[1]);
        }
        if close {
            builder.close();
        }
    }
    builder.finish()
}

/// PNG-encodes `pixmap` with fast compression, as RGB if `opaque`.
fn encode_png(pixmap: Pixmap, opaque: bool) -> Result<Vec<u8>, RenderError> {
    let (width, height) = (pixmap.width(), pixmap.height());
    let mut data = pixmap.take_demultiplied();
    let color = if opaque {
        // Every pixel is opaque (drawn over an opaque background): drop alpha.
        let mut write = 0;
        for read in (0..data.len()).step_by(4) {
            data.copy_within(read..read + 3, write);
            write += 3;
        }
        data.truncate(write);
        png::ColorType::Rgb
    } else {
        png::ColorType::Rgba
    };
    let encode = || -> Result<Vec<u8>, png::EncodingError> {
        let mut bytes = Vec::new();
        let mut encoder = png::Encoder::new(&mut bytes, width, height);
        encoder.set_color(color);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_compression(png::Compression::Fast);
        let mut writer = encoder.write_header()?;
        writer.write_image_data(&data)?;
        writer.finish()?;
        Ok(bytes)
    };
    encode().map_err(|e| RenderError::PngEncoding {
        message: e.to_string(),
    })
}

/// Renders `mesh` to an SVG document and returns its text.
///
/// The document is `width` × `height` user units (pixels), with an optional
/// background `<rect>` followed by one `<g>` holding one `<polygon>` per
/// triangle in back-to-front order, each stroked with the edge colour. With
/// [`ColorBy::EdgeNormalAngle`] the polygons are not stroked; instead each
/// edge is one `<line>`, placed after the last polygon containing it.
/// Small faces are outlined fainter (by their mean edge length on the
/// picture, as [`render_png`] fades each edge by its length) and the smallest
/// not at all; lines too short to draw are left out.
/// Coordinates are written with two decimals.
///
/// # Errors
///
/// As for [`render_png`].
pub fn render_svg(mesh: &Mesh, options: &RenderOptions) -> Result<String, RenderError> {
    let scene = Scene::new(mesh, options)?;
    let (w, h) = (options.width, options.height);
    let mut document = Document::new()
        .set("width", w)
        .set("height", h)
        .set("viewBox", (0, 0, w, h));
    let [r, g, b, a] = options.background;
    if a > 0 {
        let mut background = Rectangle::new()
            .set("width", w)
            .set("height", h)
            .set("fill", hex([r, g, b]));
        if a < 255 {
            background = background.set("fill-opacity", opacity(a));
        }
        document = document.add(background);
    }

    let draw_edges = options.line_width > 0.0;
    let per_edge = options.color_by == ColorBy::EdgeNormalAngle;
    let mut group = Group::new();
    if draw_edges {
        let [r, g, b, a] = options.edge_color;
        group = group
            .set("stroke", hex([r, g, b]))
            .set("stroke-width", options.line_width)
            .set("stroke-linejoin", "round")
            .set("stroke-linecap", "round");
        if a < 255 {
            group = group.set("stroke-opacity", opacity(a));
        }
    } else {
        group = group.set("stroke", "none");
    }
    for face in &scene.faces {
        let [p0, p1, p2] = face.points;
        let points = format!(
            "{:.2},{:.2} {:.2},{:.2} {:.2},{:.2}",
            p0[0], p0[1], p1[0], p1[1], p2[0], p2[1]
        );
        let mut polygon = Polygon::new()
            .set("points", points)
            .set("fill", hex(face.fill));
        if per_edge && draw_edges {
            // The edges follow as separately coloured lines.
            polygon = polygon.set("stroke", "none");
        } else if draw_edges && face.outline_fade == 0.0 {
            // Too small on the picture to outline: its shading shows it.
            polygon = polygon.set("stroke", "none");
        } else if draw_edges && face.outline_fade < 1.0 {
            // Both faces of an edge outline it: each at the opacity that, laid
            // twice, gives the faded edge's.
            let alpha = f32::from(faded(options.edge_color[3], face.outline_fade)) / 255.0;
            let once = 1.0 - (1.0 - alpha).sqrt();
            polygon = polygon.set("stroke-opacity", format!("{once:.3}"));
        }
        group = group.add(polygon);
        if per_edge && draw_edges {
            for ([r, g, b, a], [p, q]) in face.drawn_edges() {
                let mut line = Line::new()
                    .set("x1", format!("{:.2}", p[0]))
                    .set("y1", format!("{:.2}", p[1]))
                    .set("x2", format!("{:.2}", q[0]))
                    .set("y2", format!("{:.2}", q[1]))
                    .set("stroke", hex([r, g, b]));
                if a < 255 {
                    line = line.set("stroke-opacity", opacity(a));
                }
                group = group.add(line);
            }
        }
    }
    document = document.add(group);
    Ok(format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n{document}\n"
    ))
}

/// The picture formats [`render_to_file`] writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PictureFormat {
    /// A raster image.
    Png,
    /// A vector image.
    Svg,
}

/// The format [`render_to_file`] would write to `path`, by its extension (any case); callers
/// check it before the work that makes the mesh.
///
/// # Errors
///
/// [`RenderError::UnsupportedExtension`] unless the name ends in `.png` or `.svg`.
pub fn picture_format(path: &Path) -> Result<PictureFormat, RenderError> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match extension.as_deref() {
        Some("png") => Ok(PictureFormat::Png),
        Some("svg") => Ok(PictureFormat::Svg),
        _ => Err(RenderError::UnsupportedExtension {
            path: path.to_path_buf(),
        }),
    }
}

/// Renders `mesh` and writes the picture to `path`, as PNG if the path ends
/// in `.png` and as SVG if it ends in `.svg` (case-insensitive).
///
/// The extension is checked before anything is rendered; the file is only
/// created once rendering has succeeded.
///
/// # Errors
///
/// [`RenderError::UnsupportedExtension`] for any other extension,
/// [`RenderError::Io`] if the file cannot be written, and otherwise as for
/// [`render_png`].
pub fn render_to_file(
    mesh: &Mesh,
    path: impl AsRef<Path>,
    options: &RenderOptions,
) -> Result<(), RenderError> {
    let path = path.as_ref();
    let bytes = match picture_format(path)? {
        PictureFormat::Png => render_png(mesh, options)?,
        PictureFormat::Svg => render_svg(mesh, options)?.into_bytes(),
    };
    std::fs::write(path, bytes).map_err(|source| RenderError::Io {
        path: path.to_path_buf(),
        source,
    })
}

// ---------------------------------------------------------------------------
// Scene preparation shared by the PNG and SVG back ends.

/// One triangle ready to draw: pixel coordinates (y downwards) and colours.
struct Face {
    /// Index of the triangle in [`Mesh::triangles`] (read by the tests).
    #[cfg_attr(not(test), allow(dead_code))]
    triangle: usize,
    points: [[f32; 2]; 3],
    fill: [u8; 3],
    /// RGBA colours of the edges `points[k] → points[k + 1]`, their alpha
    /// already faded by the edge's length on the picture (0: not drawn).
    edge_colors: [[u8; 4]; 3],
    /// Opacity factor of the outline of the face as a whole (SVG polygons),
    /// from its mean edge length on the picture.
    outline_fade: f32,
    /// Whether edge `k` is drawn with this face. Each edge is drawn once,
    /// with the last face containing it in drawing order: by then the fills
    /// of all its faces are down, and anything drawn later is nearer the
    /// camera and may rightly cover it.
    owned: [bool; 3],
}

impl Face {
    /// The edges `points[k] → points[k + 1]`, `k = 0, 1, 2`.
    fn edges(&self) -> [[[f32; 2]; 2]; 3] {
        let [a, b, c] = self.points;
        [[a, b], [b, c], [c, a]]
    }

    /// The edges drawn with this face, with their colours (edges faded out
    /// entirely are left out).
    fn drawn_edges(&self) -> impl Iterator<Item = ([u8; 4], [[f32; 2]; 2])> + '_ {
        (0..3)
            .filter(|&k| self.owned[k] && self.edge_colors[k][3] > 0)
            .map(|k| (self.edge_colors[k], self.edges()[k]))
    }
}

/// The triangles in drawing order (back to front).
struct Scene {
    faces: Vec<Face>,
}

type V3 = [f64; 3];

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}

fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// `a` scaled to unit length, or `None` if it is zero or not finite.
fn normalized(a: V3) -> Option<V3> {
    let n = norm(a);
    (n.is_finite() && n > 0.0).then(|| scale(a, 1.0 / n))
}

/// Unsigned angle between `a` and `b` in radians (robust for nearly
/// parallel vectors); 0 if either is zero.
fn angle_between(a: V3, b: V3) -> f64 {
    norm(cross(a, b)).atan2(dot(a, b))
}

/// Orthonormal camera frame and projection parameters.
struct Camera {
    centre: V3,
    right: V3,
    up: V3,
    /// Unit vector from the centre towards the camera.
    back: V3,
    /// Pixels per model unit (orthographic) or focal length in pixels (perspective).
    pixels: f64,
    /// Camera distance from the centre, for perspective.
    distance: Option<f64>,
    half_width: f64,
    half_height: f64,
}

impl Camera {
    /// Pixel coordinates and depth (larger = nearer the camera) of `p`.
    fn project(&self, p: V3) -> ([f64; 2], f64) {
        let q = sub(p, self.centre);
        let (x, y, z) = (dot(q, self.right), dot(q, self.up), dot(q, self.back));
        match self.distance {
            None => (
                [
                    self.half_width + self.pixels * x,
                    self.half_height - self.pixels * y,
                ],
                z,
            ),
            Some(d) => {
                let ahead = d - z; // > 0: the mesh lies inside the bounding sphere.
                let f = self.pixels / ahead;
                ([self.half_width + f * x, self.half_height - f * y], -ahead)
            }
        }
    }

    /// Unit vector from `p` towards the camera.
    fn towards_camera(&self, p: V3) -> V3 {
        match self.distance {
            None => self.back,
            Some(d) => {
                let eye = [
                    self.centre[0] + d * self.back[0],
                    self.centre[1] + d * self.back[1],
                    self.centre[2] + d * self.back[2],
                ];
                normalized(sub(eye, p)).unwrap_or(self.back)
            }
        }
    }
}

/// Whether `options` can be drawn (a size in range, a finite line width and margin);
/// callers check it before the work that makes the mesh.
pub(crate) fn check_options(options: &RenderOptions) -> Result<(), RenderError> {
    let (width, height) = (options.width, options.height);
    if width == 0 || height == 0 || width > MAX_IMAGE_SIZE || height > MAX_IMAGE_SIZE {
        return Err(RenderError::BadSize { width, height });
    }
    if !options.line_width.is_finite() || options.line_width < 0.0 {
        return Err(RenderError::InvalidOption {
            name: "line_width",
            reason: format!(
                "{} is not allowed; use a finite width of 0 (no edges) or more pixels",
                options.line_width
            ),
        });
    }
    if !(options.margin.is_finite() && (0.0..0.5).contains(&options.margin)) {
        return Err(RenderError::InvalidOption {
            name: "margin",
            reason: format!(
                "{} is not allowed; the margin is a fraction of the smaller image side, at least 0 and below 0.5",
                options.margin
            ),
        });
    }
    Ok(())
}

/// Builds the camera frame for `view`; `centre` and `radius` describe the
/// bounding sphere, `radius > 0`.
fn camera(
    view: &View,
    options: &RenderOptions,
    centre: V3,
    radius: f64,
) -> Result<Camera, RenderError> {
    let (direction, up, fov) = match *view {
        View::Orthographic { direction, up } => (direction, up, None),
        View::Perspective {
            direction,
            up,
            fov_degrees,
        } => (direction, up, Some(fov_degrees)),
    };
    let invalid = |reason: String| RenderError::InvalidView { reason };
    if direction.iter().chain(&up).any(|c| !c.is_finite()) {
        return Err(invalid(format!(
            "direction {direction:?} and up {up:?} must have finite components"
        )));
    }
    let back = normalized(direction).ok_or_else(|| {
        invalid(format!(
            "direction {direction:?} has zero length; it must point from the mesh towards the camera"
        ))
    })?;
    // Right = up × back; if `up` gives no usable perpendicular, fall back to
    // the coordinate axis least aligned with the direction.
    let right = normalized(cross(up, back))
        .filter(|_| norm(cross(back, up)) > 1e-9 * norm(up))
        .unwrap_or_else(|| {
            let axis = (0..3)
                .min_by(|&i, &j| back[i].abs().total_cmp(&back[j].abs()))
                .unwrap_or(2);
            let mut e = [0.0; 3];
            e[axis] = 1.0;
            normalized(cross(e, back)).unwrap_or([1.0, 0.0, 0.0])
        });
    let up = cross(back, right);

    let (w, h) = (f64::from(options.width), f64::from(options.height));
    let disc = 0.5 * w.min(h) * (1.0 - 2.0 * options.margin);
    let (pixels, distance) = match fov {
        None => (disc / radius, None),
        Some(fov) => {
            if !(fov.is_finite() && fov > 0.0 && fov < 180.0) {
                return Err(invalid(format!(
                    "field of view {fov}° is not allowed; it must lie strictly between 0° and 180°"
                )));
            }
            let half = 0.5 * fov.to_radians();
            // At this distance the sphere's silhouette cone has half-angle `half`,
            // so the sphere projects to a disc of `disc` pixels radius.
            (disc / half.tan(), Some(radius / half.sin()))
        }
    };
    Ok(Camera {
        centre,
        right,
        up,
        back,
        pixels,
        distance,
        half_width: 0.5 * w,
        half_height: 0.5 * h,
    })
}

impl Scene {
    fn new(mesh: &Mesh, options: &RenderOptions) -> Result<Scene, RenderError> {
        check_options(options)?;
        let n = mesh.vertices.len();
        if mesh.triangles.is_empty() {
            return Err(RenderError::EmptyMesh { vertices: n });
        }
        if let Some((index, &position)) = mesh
            .vertices
            .iter()
            .enumerate()
            .find(|(_, p)| p.iter().any(|c| !c.is_finite()))
        {
            return Err(RenderError::NonFiniteVertex { index, position });
        }
        for (triangle, t) in mesh.triangles.iter().enumerate() {
            if let Some(&vertex) = t.iter().find(|&&v| v as usize >= n) {
                return Err(RenderError::IndexOutOfRange {
                    triangle,
                    vertex,
                    vertex_count: n,
                });
            }
        }
        if options.color_by == ColorBy::EdgeNormalAngle {
            if mesh.normals.len() != n {
                return Err(RenderError::MissingNormals {
                    normals: mesh.normals.len(),
                    vertices: n,
                });
            }
            if let Some((index, &normal)) = mesh
                .normals
                .iter()
                .enumerate()
                .find(|(_, p)| p.iter().any(|c| !c.is_finite()))
            {
                return Err(RenderError::NonFiniteNormal { index, normal });
            }
        }

        // Bounding sphere of all vertices (used by a triangle or not), so
        // that a subset of the triangles over the same vertex list is framed
        // exactly like the whole mesh.
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &mesh.vertices {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let centre = [
            0.5 * lo[0] + 0.5 * hi[0],
            0.5 * lo[1] + 0.5 * hi[1],
            0.5 * lo[2] + 0.5 * hi[2],
        ];
        let radius = mesh
            .vertices
            .iter()
            .map(|&p| norm(sub(p, centre)))
            .fold(0.0_f64, f64::max);
        if !radius.is_finite() {
            return Err(RenderError::ExtentOverflow);
        }
        let radius = if radius > 0.0 { radius } else { 1.0 };
        let camera = camera(&options.view, options, centre, radius)?;

        let projected: Vec<([f64; 2], f64)> =
            mesh.vertices.iter().map(|&p| camera.project(p)).collect();

        // Depth of each face's centroid; draw the farthest first. The index
        // breaks ties, so the order (and the output) is fully deterministic.
        let mut order: Vec<(f64, usize)> = mesh
            .triangles
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let depth = t.iter().map(|&v| projected[v as usize].1).sum::<f64>() / 3.0;
                (depth, i)
            })
            .collect();
        order.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));

        let mut faces: Vec<Face> = order
            .iter()
            .map(|&(_, i)| {
                let t = mesh.triangles[i];
                let [a, b, c] = t.map(|v| mesh.vertices[v as usize]);
                let points = t.map(|v| {
                    let [x, y] = projected[v as usize].0;
                    [x as f32, y as f32]
                });
                let centroid = scale(
                    [a[0] + b[0] + c[0], a[1] + b[1] + c[1], a[2] + b[2] + c[2]],
                    1.0 / 3.0,
                );
                // Cosine between the face normal and the direction to the camera:
                // positive for front faces. Degenerate faces count as edge-on.
                let facing = normalized(cross(sub(b, a), sub(c, a)))
                    .map_or(0.0, |nrm| dot(nrm, camera.towards_camera(centroid)));
                let fill = match options.color_by {
                    ColorBy::MinAngle => {
                        let angle = min_interior_angle(a, b, c).to_degrees();
                        shade_color(min_angle_ramp(angle / MIN_ANGLE_RAMP_MAX_DEGREES), facing)
                    }
                    ColorBy::None | ColorBy::EdgeNormalAngle => plain_face(facing),
                };
                let edge_colors = match options.color_by {
                    ColorBy::EdgeNormalAngle => [0, 1, 2].map(|k| {
                        let (na, nb) = (
                            mesh.normals[t[k] as usize],
                            mesh.normals[t[(k + 1) % 3] as usize],
                        );
                        let angle = if norm(na) > 0.0 && norm(nb) > 0.0 {
                            angle_between(na, nb).to_degrees()
                        } else {
                            180.0
                        };
                        // Whole degrees, so that edges share colours and can
                        // be drawn together.
                        let [r, g, b] =
                            edge_ramp(angle.round() / EDGE_NORMAL_ANGLE_RAMP_MAX_DEGREES);
                        [r, g, b, 255]
                    }),
                    ColorBy::None | ColorBy::MinAngle => [options.edge_color; 3],
                };
                let lengths = [0, 1, 2].map(|k| {
                    let (p, q) = (points[k], points[(k + 1) % 3]);
                    (p[0] - q[0]).hypot(p[1] - q[1])
                });
                let mut edge_colors = edge_colors;
                for (color, &length) in edge_colors.iter_mut().zip(&lengths) {
                    color[3] = faded(color[3], edge_fade(length, options.line_width));
                }
                let mean = (lengths[0] + lengths[1] + lengths[2]) / 3.0;
                Face {
                    triangle: i,
                    points,
                    fill,
                    edge_colors,
                    outline_fade: edge_fade(mean, options.line_width),
                    owned: [true; 3],
                }
            })
            .collect();

        // Each undirected edge is drawn with the last face containing it:
        // sort the edge slots (3 · position + k) by edge, then by slot.
        let mut slots: Vec<(u64, usize)> = order
            .iter()
            .enumerate()
            .flat_map(|(position, &(_, i))| {
                let t = mesh.triangles[i];
                (0..3).map(move |k| {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    let key = (u64::from(a.min(b)) << 32) | u64::from(a.max(b));
                    (key, 3 * position + k)
                })
            })
            .collect();
        slots.sort_unstable();
        for pair in slots.windows(2) {
            if pair[0].0 == pair[1].0 {
                let slot = pair[0].1;
                faces[slot / 3].owned[slot % 3] = false;
            }
        }
        Ok(Scene { faces })
    }
}

/// The opacity factor of an edge `length` pixels long on the picture, drawn
/// `line_width` wide: 0 up to [`EDGE_HIDDEN_BELOW`] widths, 1 from
/// [`EDGE_FULL_FROM`] widths, linear between, in steps of 1/16 (widths under
/// a pixel count as a pixel). A length that is not a number counts as long.
fn edge_fade(length: f32, line_width: f32) -> f32 {
    let unit = line_width.max(1.0);
    let t = (length / unit - EDGE_HIDDEN_BELOW) / (EDGE_FULL_FROM - EDGE_HIDDEN_BELOW);
    if t.is_nan() {
        return 1.0;
    }
    (t.clamp(0.0, 1.0) * FADE_STEPS).round() / FADE_STEPS
}

/// `alpha` times `fade`, rounded.
fn faded(alpha: u8, fade: f32) -> u8 {
    (f32::from(alpha) * fade).round() as u8
}

/// Smallest interior angle of the triangle `abc` in radians (0 if degenerate).
fn min_interior_angle(a: V3, b: V3, c: V3) -> f64 {
    let at_a = angle_between(sub(b, a), sub(c, a));
    let at_b = angle_between(sub(c, b), sub(a, b));
    let at_c = angle_between(sub(a, c), sub(b, c));
    at_a.min(at_b).min(at_c)
}

/// Linear interpolation through evenly spaced colour stops, `t` clamped to `[0, 1]`.
fn ramp(stops: &[[f64; 3]], t: f64) -> [f64; 3] {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let x = t * (stops.len() - 1) as f64;
    let i = (x.floor() as usize).min(stops.len() - 2);
    let f = x - i as f64;
    let (p, q) = (stops[i], stops[i + 1]);
    [0, 1, 2].map(|k| p[k] + f * (q[k] - p[k]))
}

/// Red (0) – yellow (½) – blue (1), after ColorBrewer's RdYlBu.
fn min_angle_ramp(t: f64) -> [f64; 3] {
    ramp(
        &[
            [215.0, 48.0, 39.0],
            [254.0, 224.0, 144.0],
            [69.0, 117.0, 180.0],
        ],
        t,
    )
}

/// Dark blue (0) – purple (½) – red (1); dark enough to read on light faces.
fn edge_ramp(t: f64) -> [u8; 3] {
    to_u8(ramp(
        &[
            [35.0, 45.0, 110.0],
            [150.0, 40.0, 150.0],
            [225.0, 25.0, 25.0],
        ],
        t,
    ))
}

fn to_u8(c: [f64; 3]) -> [u8; 3] {
    c.map(|v| v.round().clamp(0.0, 255.0) as u8)
}

/// Lambert-style brightness for a face whose normal makes cosine `facing`
/// with the direction to the camera: front faces from 0.6 (edge-on) to 1.0
/// (facing the camera), back faces from 0.75 (edge-on) down to 0.55, light
/// enough for their edges to read.
fn brightness(facing: f64) -> f64 {
    if facing >= 0.0 {
        0.6 + 0.4 * facing
    } else {
        0.75 + 0.2 * facing
    }
}

/// A colour-ramp colour with gentler shading than the plain faces (so the
/// colour stays legible): front faces from 0.78 (edge-on) to 1.0 of it, back
/// faces mixed halfway to grey and darkened to 0.6 of it.
fn shade_color(base: [f64; 3], facing: f64) -> [u8; 3] {
    if facing >= 0.0 {
        to_u8(base.map(|v| v * (0.78 + 0.22 * facing)))
    } else {
        let grey = (base[0] + base[1] + base[2]) / 3.0;
        to_u8(base.map(|v| 0.6 * (0.5 * v + 0.5 * grey)))
    }
}

/// The plain light face colour: near-white for front faces, a darker warm
/// grey for back faces (seen through holes or past open boundaries).
fn plain_face(facing: f64) -> [u8; 3] {
    let s = brightness(facing);
    let base = if facing >= 0.0 {
        [252.0, 252.0, 255.0]
    } else {
        [235.0, 215.0, 200.0]
    };
    to_u8(base.map(|v| v * s))
}

fn hex([r, g, b]: [u8; 3]) -> String {
    format!("#{r:02x}{g:02x}{b:02x}")
}

fn opacity(alpha: u8) -> String {
    format!("{:.3}", f64::from(alpha) / 255.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use liemesh::triangulate::Provenance;
    use std::collections::HashMap;

    /// The octahedron with corners ±x, ±y, ±z, faces counter-clockwise seen from outside.
    fn octahedron() -> Mesh {
        let vertices = vec![
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ];
        let triangles = vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        with_normals(vertices, triangles)
    }

    /// The example that was this module's doctest while it was in the library.
    #[test]
    fn octahedron_in_png_and_svg() {
        let options = RenderOptions {
            width: 200,
            height: 200,
            view: View::Orthographic {
                direction: [1.0, 0.7, 0.5],
                up: [0.0, 0.0, 1.0],
            },
            color_by: ColorBy::MinAngle,
            ..RenderOptions::default()
        };
        let png = render_png(&octahedron(), &options).unwrap();
        assert!(png.starts_with(b"\x89PNG"));
        let svg = render_svg(&octahedron(), &options).unwrap();
        assert_eq!(svg.matches("<polygon").count(), 8);
    }

    fn with_normals(vertices: Vec<[f64; 3]>, triangles: Vec<[u32; 3]>) -> Mesh {
        let normals = vertices
            .iter()
            .map(|&p| normalized(p).unwrap_or([0.0, 0.0, 1.0]))
            .collect();
        let provenance = vec![
            Provenance {
                curve: Provenance::CLOSING_CURVE,
                step: 0,
                s: 0.0,
                theta: 0.0,
            };
            vertices.len()
        ];
        Mesh {
            vertices,
            normals,
            triangles,
            provenance,
        }
    }

    /// The octahedron subdivided `levels` times (each triangle into four),
    /// projected onto the unit sphere: `8 · 4^levels` triangles.
    fn icosphere(levels: u32) -> Mesh {
        let base = octahedron();
        let mut vertices = base.vertices;
        let mut triangles = base.triangles;
        for _ in 0..levels {
            let mut midpoints: HashMap<(u32, u32), u32> = HashMap::new();
            let mut midpoint = |a: u32, b: u32, vertices: &mut Vec<[f64; 3]>| -> u32 {
                let key = (a.min(b), a.max(b));
                *midpoints.entry(key).or_insert_with(|| {
                    let (p, q) = (vertices[a as usize], vertices[b as usize]);
                    let m = [p[0] + q[0], p[1] + q[1], p[2] + q[2]];
                    vertices.push(normalized(m).unwrap());
                    (vertices.len() - 1) as u32
                })
            };
            let mut next = Vec::with_capacity(4 * triangles.len());
            for &[a, b, c] in &triangles {
                let ab = midpoint(a, b, &mut vertices);
                let bc = midpoint(b, c, &mut vertices);
                let ca = midpoint(c, a, &mut vertices);
                next.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
            }
            triangles = next;
        }
        with_normals(vertices, triangles)
    }

    fn small(color_by: ColorBy) -> RenderOptions {
        RenderOptions {
            width: 240,
            height: 200,
            color_by,
            ..RenderOptions::default()
        }
    }

    fn rgba(pixmap: &Pixmap, x: u32, y: u32) -> [u8; 4] {
        let c = pixmap.pixel(x, y).unwrap().demultiply();
        [c.red(), c.green(), c.blue(), c.alpha()]
    }

    fn luma([r, g, b, _]: [u8; 4]) -> u32 {
        (u32::from(r) + u32::from(g) + u32::from(b)) / 3
    }

    #[test]
    fn icosphere_png_is_a_disc_with_dark_edges() {
        let mesh = icosphere(3);
        assert_eq!(mesh.triangles.len(), 512);
        let options = small(ColorBy::None);
        let png = render_png(&mesh, &options).unwrap();
        let pixmap = Pixmap::decode_png(&png).unwrap();
        assert_eq!((pixmap.width(), pixmap.height()), (240, 200));

        let white = [255, 255, 255, 255];
        for (x, y) in [(0, 0), (239, 0), (0, 199), (239, 199)] {
            assert_eq!(rgba(&pixmap, x, y), white, "corner ({x}, {y})");
        }
        assert_ne!(rgba(&pixmap, 120, 100), white, "centre");

        let pixels: Vec<[u8; 4]> = (0..200)
            .flat_map(|y| (0..240).map(move |x| (x, y)))
            .map(|(x, y)| rgba(&pixmap, x, y))
            .collect();
        let background = pixels.iter().filter(|&&p| p == white).count();
        let dark = pixels.iter().filter(|&&p| luma(p) < 110).count();
        assert!(background > 1000, "background pixels: {background}");
        assert!(dark > 500, "dark edge pixels: {dark}");

        // The drawn region is a disc of radius 0.45 · 200 = 90 px about the
        // centre: everything clearly outside is background, everything
        // clearly inside is drawn.
        for (i, &p) in pixels.iter().enumerate() {
            let (x, y) = ((i % 240) as f64 + 0.5, (i / 240) as f64 + 0.5);
            let r = ((x - 120.0).powi(2) + (y - 100.0).powi(2)).sqrt();
            if r > 93.0 {
                assert_eq!(p, white, "pixel ({x}, {y}) at radius {r:.1}");
            } else if r < 80.0 {
                assert_ne!(p, white, "pixel ({x}, {y}) at radius {r:.1}");
            }
        }
    }

    #[test]
    fn dense_meshes_read_by_their_shading() {
        // 131,072 triangles in a disc of radius 0.45 · 400 = 180 px: about a
        // pixel and a half of picture per front face. Drawing every edge in
        // the edge colour (luma 30) would make the disc nearly black.
        let mesh = icosphere(7);
        assert_eq!(mesh.triangles.len(), 131_072);
        let options = RenderOptions {
            width: 400,
            height: 400,
            ..RenderOptions::default()
        };
        let pixmap = Pixmap::decode_png(&render_png(&mesh, &options).unwrap()).unwrap();
        let (mut sum, mut count) = (0, 0);
        for y in 0..400 {
            for x in 0..400 {
                if (f64::from(x) - 199.5).hypot(f64::from(y) - 199.5) < 150.0 {
                    sum += luma(rgba(&pixmap, x, y));
                    count += 1;
                }
            }
        }
        let mean = sum / count;
        assert!(mean > 150, "mean luma inside the disc: {mean}");

        // The SVG leaves the outlines of faces that small out.
        let svg = render_svg(&mesh, &options).unwrap();
        let bare = svg.matches(r#"stroke="none""#).count();
        assert!(
            bare > mesh.triangles.len() / 2,
            "{bare} faces without outline"
        );

        // A coarse mesh keeps every edge in full, in both formats.
        let coarse = icosphere(2);
        let scene = Scene::new(&coarse, &options).unwrap();
        assert!(scene
            .faces
            .iter()
            .all(|f| f.outline_fade == 1.0 && f.edge_colors.iter().all(|c| c[3] == 255)));
        let svg = render_svg(&coarse, &options).unwrap();
        assert!(!svg.contains(r#"stroke="none""#) && !svg.contains("stroke-opacity"));
    }

    #[test]
    fn edges_fade_with_their_length_on_the_picture() {
        assert_eq!(edge_fade(0.0, 1.0), 0.0);
        assert_eq!(edge_fade(EDGE_HIDDEN_BELOW, 1.0), 0.0);
        assert_eq!(
            edge_fade(0.5 * (EDGE_HIDDEN_BELOW + EDGE_FULL_FROM), 1.0),
            0.5
        );
        assert_eq!(edge_fade(EDGE_FULL_FROM, 1.0), 1.0);
        assert_eq!(edge_fade(1e6, 1.0), 1.0);
        assert_eq!(edge_fade(f32::NAN, 1.0), 1.0);
        // Hairlines count as a pixel wide; wider lines need longer edges.
        assert_eq!(edge_fade(EDGE_FULL_FROM, 0.25), 1.0);
        assert_eq!(edge_fade(3.0 * EDGE_HIDDEN_BELOW, 3.0), 0.0);
        assert!(edge_fade(EDGE_FULL_FROM, 3.0) < 0.5);
        assert_eq!(edge_fade(3.0 * EDGE_FULL_FROM, 3.0), 1.0);
        // Monotone, in steps of 1/16.
        let mut last = 0.0;
        for i in 0..200 {
            let f = edge_fade(i as f32 * 0.1, 1.0);
            assert!(f >= last && (f * 16.0).fract() == 0.0, "{i}: {f}");
            last = f;
        }
        assert_eq!(faded(255, 0.5), 128);
        assert_eq!(faded(200, 0.0), 0);
    }

    #[test]
    fn hidden_edges_are_removed() {
        // Compare against a render of the front faces only (same vertex
        // list, hence same framing): inside the silhouette the pictures must
        // agree, so no back edge shows through.
        let mesh = icosphere(2);
        let options = RenderOptions {
            width: 160,
            height: 160,
            view: View::Orthographic {
                direction: [0.3, -1.0, 0.4],
                up: [0.0, 0.0, 1.0],
            },
            ..RenderOptions::default()
        };
        let back = normalized([0.3, -1.0, 0.4]).unwrap();
        let mut front_only = mesh.clone();
        front_only.triangles.retain(|t| {
            let [a, b, c] = t.map(|v| mesh.vertices[v as usize]);
            dot(cross(sub(b, a), sub(c, a)), back) > 0.0
        });
        assert!(front_only.triangles.len() < mesh.triangles.len());
        let full = Pixmap::decode_png(&render_png(&mesh, &options).unwrap()).unwrap();
        let front = Pixmap::decode_png(&render_png(&front_only, &options).unwrap()).unwrap();
        // The silhouette (disc of radius 0.45 · 160 = 72 px) is left out:
        // there back faces may peek out by a fraction of a pixel. Inside,
        // where two front faces meet, anti-aliased fill coverage lets a trace
        // of whatever lies below leak through the seam, so pixels may differ
        // by a few levels; a hidden edge that showed would differ by well
        // over 100 (dark grey on near-white).
        let mut worst = 0;
        for y in 0..160 {
            for x in 0..160 {
                let r = (f64::from(x) - 79.5).hypot(f64::from(y) - 79.5);
                if r > 68.0 {
                    continue;
                }
                let (a, b) = (rgba(&full, x, y), rgba(&front, x, y));
                for k in 0..4 {
                    worst = worst.max(a[k].abs_diff(b[k]));
                }
            }
        }
        assert!(worst <= 20, "largest channel difference {worst}");
    }

    #[test]
    fn color_modes_render_and_differ() {
        let mesh = icosphere(2);
        let plain = render_png(&mesh, &small(ColorBy::None)).unwrap();
        let angle = render_png(&mesh, &small(ColorBy::MinAngle)).unwrap();
        let normal = render_png(&mesh, &small(ColorBy::EdgeNormalAngle)).unwrap();
        assert_ne!(plain, angle);
        assert_ne!(plain, normal);
        assert_ne!(angle, normal);
        // MinAngle faces of an icosphere are between 30° and 60°: no pure grey
        // in the interior, some saturated colour instead.
        let pixmap = Pixmap::decode_png(&angle).unwrap();
        let colourful = (0..200)
            .flat_map(|y| (0..240).map(move |x| (x, y)))
            .map(|(x, y)| rgba(&pixmap, x, y))
            .filter(|&[r, g, b, _]| r.max(g).max(b) - r.min(g).min(b) > 60)
            .count();
        assert!(colourful > 5000, "coloured pixels: {colourful}");
    }

    #[test]
    fn perspective_view_renders() {
        let mesh = icosphere(2);
        let options = RenderOptions {
            width: 120,
            height: 120,
            view: View::Perspective {
                direction: [1.0, 1.0, 1.0],
                up: [0.0, 0.0, 1.0],
                fov_degrees: 40.0,
            },
            ..RenderOptions::default()
        };
        let pixmap = Pixmap::decode_png(&render_png(&mesh, &options).unwrap()).unwrap();
        assert_eq!(rgba(&pixmap, 0, 0), [255, 255, 255, 255]);
        assert_ne!(rgba(&pixmap, 60, 60), [255, 255, 255, 255]);
    }

    #[test]
    fn svg_has_one_polygon_per_triangle() {
        let mesh = icosphere(2);
        let n = mesh.triangles.len();
        let svg = render_svg(&mesh, &small(ColorBy::None)).unwrap();
        assert!(svg.starts_with("<?xml"));
        assert!(svg.contains("<svg"));
        assert!(svg.contains(r#"viewBox="0 0 240 200""#));
        assert!(svg.trim_end().ends_with("</svg>"));
        assert_eq!(svg.matches("<polygon ").count(), n);
        assert_eq!(svg.matches("<line ").count(), 0);
        assert_eq!(svg.matches("<rect ").count(), 1);

        // Each edge of the closed surface is drawn once: 3n/2 lines.
        let svg = render_svg(&mesh, &small(ColorBy::EdgeNormalAngle)).unwrap();
        assert_eq!(svg.matches("<polygon ").count(), n);
        assert_eq!(svg.matches("<line ").count(), 3 * n / 2);

        let transparent = RenderOptions {
            background: [0, 0, 0, 0],
            line_width: 0.0,
            ..small(ColorBy::MinAngle)
        };
        let svg = render_svg(&mesh, &transparent).unwrap();
        assert_eq!(svg.matches("<rect ").count(), 0);
        assert_eq!(svg.matches("<polygon ").count(), n);
        assert!(!svg.contains("NaN") && !svg.contains("inf"));
    }

    fn from_above() -> RenderOptions {
        RenderOptions {
            view: View::Orthographic {
                direction: [0.0, 0.0, 1.0],
                up: [0.0, 1.0, 0.0],
            },
            ..small(ColorBy::None)
        }
    }

    fn x_extent(face: &Face) -> f32 {
        let xs = face.points.map(|p| p[0]);
        xs[0].max(xs[1]).max(xs[2]) - xs[0].min(xs[1]).min(xs[2])
    }

    #[test]
    fn faces_are_drawn_back_to_front() {
        // Seen from +z: a small near triangle (z = 1, index 0) and a large
        // far one (z = -1, index 1). The far one must be drawn first.
        let vertices = vec![
            [0.0, 0.0, 1.0],
            [0.5, 0.0, 1.0],
            [0.0, 0.5, 1.0],
            [0.0, 0.0, -1.0],
            [1.0, 0.0, -1.0],
            [0.0, 1.0, -1.0],
        ];
        let mesh = with_normals(vertices, vec![[0, 1, 2], [3, 4, 5]]);
        let options = from_above();
        let scene = Scene::new(&mesh, &options).unwrap();
        let order: Vec<usize> = scene.faces.iter().map(|f| f.triangle).collect();
        assert_eq!(order, [1, 0]);
        assert!(x_extent(&scene.faces[0]) > 1.5 * x_extent(&scene.faces[1]));

        // The SVG lists the polygons in the same order.
        let svg = render_svg(&mesh, &options).unwrap();
        let polygons: Vec<&str> = svg.lines().filter(|l| l.contains("<polygon")).collect();
        assert_eq!(polygons.len(), 2);
        for (polygon, face) in polygons.iter().zip(&scene.faces) {
            let [p0, p1, p2] = face.points;
            let points = format!(
                "{:.2},{:.2} {:.2},{:.2} {:.2},{:.2}",
                p0[0], p0[1], p1[0], p1[1], p2[0], p2[1]
            );
            assert!(polygon.contains(&points), "{polygon} vs {points}");
        }
    }

    #[test]
    fn equal_depths_are_drawn_in_index_order() {
        // Overlapping triangles in one plane facing the camera, all with the
        // same centroid depth: drawn in index order.
        let vertices = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.2, 0.1, 0.0],
            [0.6, 0.1, 0.0],
            [0.2, 0.5, 0.0],
        ];
        let triangles = vec![[3, 4, 5], [0, 1, 2], [4, 5, 3], [1, 2, 0]];
        let mesh = with_normals(vertices, triangles);
        let scene = Scene::new(&mesh, &from_above()).unwrap();
        let order: Vec<usize> = scene.faces.iter().map(|f| f.triangle).collect();
        assert_eq!(order, [0, 1, 2, 3]);
    }

    #[test]
    fn render_to_file_picks_format_by_extension() {
        let dir = std::env::temp_dir().join(format!("liemesh-render-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mesh = octahedron();
        let options = small(ColorBy::None);

        let png = dir.join("octahedron.PNG");
        render_to_file(&mesh, &png, &options).unwrap();
        assert_eq!(
            std::fs::read(&png).unwrap(),
            render_png(&mesh, &options).unwrap()
        );

        let svg = dir.join("octahedron.svg");
        render_to_file(&mesh, &svg, &options).unwrap();
        assert_eq!(
            std::fs::read_to_string(&svg).unwrap(),
            render_svg(&mesh, &options).unwrap()
        );

        for bad in ["octahedron.jpg", "octahedron", "png"] {
            let err = render_to_file(&mesh, dir.join(bad), &options).unwrap_err();
            assert!(
                matches!(err, RenderError::UnsupportedExtension { .. }),
                "{err}"
            );
            let message = err.to_string();
            assert!(
                message.contains(".png") && message.contains(".svg"),
                "{message}"
            );
            assert!(!dir.join(bad).exists());
        }

        let missing = dir.join("no-such-dir").join("x.svg");
        let err = render_to_file(&mesh, &missing, &options).unwrap_err();
        assert!(matches!(err, RenderError::Io { .. }), "{err}");
        assert!(err.to_string().contains("no-such-dir"), "{err}");

        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn malformed_meshes_are_errors() {
        let options = small(ColorBy::None);

        let err = render_png(&Mesh::default(), &options).unwrap_err();
        assert!(
            matches!(err, RenderError::EmptyMesh { vertices: 0 }),
            "{err}"
        );
        let mut no_triangles = octahedron();
        no_triangles.triangles.clear();
        assert!(matches!(
            render_svg(&no_triangles, &options),
            Err(RenderError::EmptyMesh { vertices: 6 })
        ));

        let mut out_of_range = octahedron();
        out_of_range.triangles[5] = [0, 6, 1];
        let err = render_png(&out_of_range, &options).unwrap_err();
        assert!(
            matches!(
                err,
                RenderError::IndexOutOfRange {
                    triangle: 5,
                    vertex: 6,
                    vertex_count: 6
                }
            ),
            "{err}"
        );
        out_of_range.triangles[5] = [u32::MAX, 0, 1];
        assert!(render_svg(&out_of_range, &options).is_err());

        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mut non_finite = octahedron();
            non_finite.vertices[3][1] = bad;
            let err = render_png(&non_finite, &options).unwrap_err();
            assert!(
                matches!(err, RenderError::NonFiniteVertex { index: 3, .. }),
                "{err}"
            );
        }

        let mut huge = octahedron();
        huge.vertices[0] = [f64::MAX, 0.0, 0.0];
        huge.vertices[1] = [-f64::MAX, 0.0, 0.0];
        assert!(matches!(
            render_png(&huge, &options),
            Err(RenderError::ExtentOverflow)
        ));

        let mut few_normals = octahedron();
        few_normals.normals.pop();
        assert!(render_png(&few_normals, &options).is_ok());
        assert!(matches!(
            render_png(&few_normals, &small(ColorBy::EdgeNormalAngle)),
            Err(RenderError::MissingNormals {
                normals: 5,
                vertices: 6
            })
        ));
        let mut nan_normal = octahedron();
        nan_normal.normals[2][0] = f64::NAN;
        assert!(matches!(
            render_svg(&nan_normal, &small(ColorBy::EdgeNormalAngle)),
            Err(RenderError::NonFiniteNormal { index: 2, .. })
        ));
    }

    #[test]
    fn degenerate_geometry_still_renders() {
        // A single point, a zero-area triangle and an edge-on face.
        let point = with_normals(vec![[1.0, 2.0, 3.0]], vec![[0, 0, 0]]);
        let line = with_normals(
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]],
            vec![[0, 1, 2]],
        );
        for mesh in [point, line] {
            for color_by in [ColorBy::None, ColorBy::MinAngle, ColorBy::EdgeNormalAngle] {
                render_png(&mesh, &small(color_by)).unwrap();
                render_svg(&mesh, &small(color_by)).unwrap();
            }
        }
        let edge_on = RenderOptions {
            view: View::Orthographic {
                direction: [0.0, 1.0, 0.0],
                up: [0.0, 0.0, 1.0],
            },
            ..small(ColorBy::None)
        };
        let flat = with_normals(
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
            vec![[0, 1, 2]],
        );
        let svg = render_svg(&flat, &edge_on).unwrap();
        assert!(!svg.contains("NaN"));
    }

    #[test]
    fn bad_options_are_errors() {
        let mesh = octahedron();
        for (width, height) in [(0, 10), (10, 0), (MAX_IMAGE_SIZE + 1, 10), (10, u32::MAX)] {
            let options = RenderOptions {
                width,
                height,
                ..RenderOptions::default()
            };
            let err = render_png(&mesh, &options).unwrap_err();
            assert!(matches!(err, RenderError::BadSize { .. }), "{err}");
            assert!(err.to_string().contains("16384"), "{err}");
            assert!(render_svg(&mesh, &options).is_err());
        }

        let views = [
            View::Orthographic {
                direction: [0.0, 0.0, 0.0],
                up: [0.0, 0.0, 1.0],
            },
            View::Orthographic {
                direction: [f64::NAN, 0.0, 1.0],
                up: [0.0, 0.0, 1.0],
            },
            View::Perspective {
                direction: [1.0, 0.0, 0.0],
                up: [0.0, 0.0, 1.0],
                fov_degrees: 180.0,
            },
            View::Perspective {
                direction: [1.0, 0.0, 0.0],
                up: [0.0, 0.0, 1.0],
                fov_degrees: 0.0,
            },
        ];
        for view in views {
            let options = RenderOptions {
                view,
                ..small(ColorBy::None)
            };
            let err = render_png(&mesh, &options).unwrap_err();
            assert!(
                matches!(err, RenderError::InvalidView { .. }),
                "{view:?}: {err}"
            );
        }

        // `up` parallel to the direction falls back to another axis.
        let options = RenderOptions {
            view: View::Orthographic {
                direction: [0.0, 0.0, 2.0],
                up: [0.0, 0.0, 1.0],
            },
            ..small(ColorBy::None)
        };
        render_png(&mesh, &options).unwrap();

        for line_width in [-1.0, f32::NAN, f32::INFINITY] {
            let options = RenderOptions {
                line_width,
                ..small(ColorBy::None)
            };
            assert!(matches!(
                render_png(&mesh, &options),
                Err(RenderError::InvalidOption {
                    name: "line_width",
                    ..
                })
            ));
        }
        for margin in [-0.1, 0.5, f64::NAN] {
            let options = RenderOptions {
                margin,
                ..small(ColorBy::None)
            };
            assert!(matches!(
                render_svg(&mesh, &options),
                Err(RenderError::InvalidOption { name: "margin", .. })
            ));
        }
    }

    #[test]
    fn every_edge_is_drawn_once_by_its_last_face() {
        // A closed surface and an open one (the upper half of the sphere).
        let sphere = icosphere(2);
        let mut cap = sphere.clone();
        cap.triangles
            .retain(|t| t.iter().all(|&v| cap.vertices[v as usize][2] >= 0.0));
        for mesh in [sphere, cap] {
            let options = small(ColorBy::None);
            let scene = Scene::new(&mesh, &options).unwrap();
            let order: Vec<[u32; 3]> = scene
                .faces
                .iter()
                .map(|face| mesh.triangles[face.triangle])
                .collect();
            let mut last: HashMap<(u32, u32), usize> = HashMap::new();
            for (position, t) in order.iter().enumerate() {
                for k in 0..3 {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    last.insert((a.min(b), a.max(b)), position);
                }
            }
            let mut drawn = 0;
            for (position, (t, face)) in order.iter().zip(&scene.faces).enumerate() {
                for k in 0..3 {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    let owner = last[&(a.min(b), a.max(b))] == position;
                    assert_eq!(face.owned[k], owner, "face {position}, edge {k}");
                    drawn += usize::from(owner);
                }
            }
            assert_eq!(drawn, last.len());
        }
    }

    #[test]
    fn batching_does_not_change_the_picture() {
        let mesh = icosphere(3);
        for (color_by, line_width) in [
            (ColorBy::None, 1.0),
            (ColorBy::MinAngle, 2.5),
            (ColorBy::EdgeNormalAngle, 1.0),
            (ColorBy::None, 0.5),
            (ColorBy::None, 0.0),
        ] {
            let options = RenderOptions {
                line_width,
                ..small(color_by)
            };
            let scene = Scene::new(&mesh, &options).unwrap();
            let one_by_one = rasterize(&scene, &options, 1).unwrap();
            let batched = rasterize(&scene, &options, Painter::MAX_BATCH).unwrap();
            assert!(
                one_by_one.data() == batched.data(),
                "{color_by:?}, line width {line_width}"
            );
        }
    }

    #[test]
    fn open_surfaces_show_their_inside() {
        // The lower half of the sphere seen from above and to the side: part
        // of its inside (back faces, drawn darker and warmer) is visible.
        let sphere = icosphere(3);
        let mut bowl = sphere.clone();
        bowl.triangles
            .retain(|t| t.iter().all(|&v| bowl.vertices[v as usize][2] <= 0.0));
        let options = RenderOptions {
            view: View::Orthographic {
                direction: [0.0, -1.0, 1.5],
                up: [0.0, 0.0, 1.0],
            },
            ..small(ColorBy::None)
        };
        let pixmap = Pixmap::decode_png(&render_png(&bowl, &options).unwrap()).unwrap();
        let (mut warm, mut cool) = (0, 0);
        for y in 0..pixmap.height() {
            for x in 0..pixmap.width() {
                let [r, g, b, _] = rgba(&pixmap, x, y);
                if u16::from(r) > u16::from(b) + 10 {
                    warm += 1;
                } else if b >= r && g >= r && luma([r, g, b, 255]) > 120 {
                    cool += 1;
                }
            }
        }
        // Background counts as cool (white); inside and outside both show.
        assert!(warm > 2000, "inside pixels: {warm}");
        assert!(cool > 2000, "outside and background pixels: {cool}");
    }
}
