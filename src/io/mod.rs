//! Reading and writing: mesh files, run reports, and (with the `toml` feature) invariant files.
//!
//! # Mesh files
//!
//! [`write_mesh`] and [`read_mesh`] pick the format from the file extension
//! (see [`MeshFormat::from_path`]); the per-format functions ([`write_ply`],
//! [`write_obj`], [`write_stl`], [`read_ply`], [`read_obj`]) work on any
//! [`Write`] or [`BufRead`] stream.
//!
//! | format | writes | reads | keeps |
//! | --- | --- | --- | --- |
//! | PLY | binary little-endian (default) or ASCII | ASCII, binary little- and big-endian | positions, normals, provenance, triangles |
//! | OBJ | ASCII | ASCII | positions, normals, triangles |
//! | STL | binary | — | triangles with facet normals (`f32`) |
//!
//! A mesh read from a file that does not record provenance (OBJ; PLY without
//! the `curve` property) has [`Provenance::UNKNOWN`](crate::Provenance::UNKNOWN)
//! for every vertex rather than a made-up origin.
//!
//! Floating-point values are written so that reading them back gives the same
//! `f64` bits: PLY stores them as `double`, OBJ and ASCII PLY print them with
//! Rust's shortest round-trip formatting. Output is deterministic: the same
//! mesh always gives the same bytes.
//!
//! Every writer refuses a mesh whose vectors disagree in length, whose
//! triangles index past the vertices, or which holds NaN or infinite values,
//! with [`IoError::InvalidMesh`]; every reader reports problems in the file
//! as an [`IoError`] naming the line or element, and never panics.

use std::borrow::Cow;
use std::fmt;
use std::fs::{self, File};
use std::io::{BufRead, BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

use crate::triangulate::Mesh;

// ---------------------------------------------------------------------------
// Submodules. Keep one `pub mod` per line, sorted; add new ones to this list.
// ---------------------------------------------------------------------------
#[cfg(feature = "toml")]
pub mod invariant_file;
pub mod obj;
pub mod ply;
pub mod report;
pub mod stl;
// ---------------------------------------------------------------------------

pub use obj::{read_obj, write_obj};
pub use ply::{read_ply, write_ply, write_ply_with, PlyEncoding, VertexVectors};
pub use stl::write_stl;

/// The mesh file formats liemesh knows, chosen by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MeshFormat {
    /// Stanford polygon format (`.ply`), binary or ASCII.
    Ply,
    /// Wavefront OBJ (`.obj`).
    Obj,
    /// Binary STL (`.stl`); write-only.
    Stl,
}

impl MeshFormat {
    /// All formats, in the order they are listed in messages.
    pub const ALL: [MeshFormat; 3] = [MeshFormat::Ply, MeshFormat::Obj, MeshFormat::Stl];

    /// Picks the format from the extension of `path`: `.ply`, `.obj` or `.stl`,
    /// in any letter case.
    ///
    /// # Errors
    ///
    /// [`IoError::UnsupportedExtension`] if the path has no extension or
    /// another one.
    pub fn from_path(path: &Path) -> Result<MeshFormat, IoError> {
        let extension = path.extension().map(|e| e.to_string_lossy().into_owned());
        let format = extension.as_deref().and_then(|e| {
            Self::ALL
                .into_iter()
                .find(|f| e.eq_ignore_ascii_case(f.extension()))
        });
        format.ok_or_else(|| IoError::UnsupportedExtension {
            path: path.to_path_buf(),
            extension,
        })
    }

    /// The usual file extension, lower case and without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            MeshFormat::Ply => "ply",
            MeshFormat::Obj => "obj",
            MeshFormat::Stl => "stl",
        }
    }
}

impl fmt::Display for MeshFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            MeshFormat::Ply => "PLY",
            MeshFormat::Obj => "OBJ",
            MeshFormat::Stl => "STL",
        })
    }
}

/// Options for [`write_mesh`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WriteOptions {
    /// Write PLY files as ASCII instead of binary little-endian (the default).
    /// Ignored for the other formats.
    pub ply_ascii: bool,
}

/// Where in a file a problem was found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Location {
    /// A line of a text file or of a PLY header, counting from 1.
    Line(u64),
    /// An element of a PLY file's body, e.g. the 8th `vertex`.
    Element {
        /// Element name from the PLY header, e.g. `vertex` or `face`.
        element: String,
        /// Index of the element among those of its kind, counting from 0.
        index: u64,
        /// Line of the element in an ASCII file, counting from 1; `None` in binary files.
        line: Option<u64>,
    },
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Line(line) => write!(f, "line {line}"),
            Location::Element {
                element,
                index,
                line,
            } => {
                if let Some(line) = line {
                    write!(f, "line {line}, ")?;
                }
                write!(f, "{element} {index} (counting from 0)")
            }
        }
    }
}

/// Everything that can go wrong while reading or writing mesh files.
///
/// Messages name the file and, for problems in its content, the line or
/// element; they are meant to be shown to a person as they are. Errors from
/// the stream functions ([`read_ply`], [`write_obj`], ...) carry an empty
/// `path`, shown as `<stream>`; [`read_mesh`] and [`write_mesh`] fill it in.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum IoError {
    /// The operating system refused or failed a read or write.
    #[error("cannot access {}: {source}; check that the path is right and that you may read or write there", show(.path))]
    Io {
        /// The file (or directory) being accessed.
        path: PathBuf,
        /// What the operating system reported.
        #[source]
        source: std::io::Error,
    },

    /// The file extension does not name a mesh format.
    #[error("{}: {}; use a file name ending in .ply, .obj or .stl (letter case does not matter)", show(.path), describe_extension(.extension.as_deref()))]
    UnsupportedExtension {
        /// The path whose extension was looked at.
        path: PathBuf,
        /// The extension found, without the dot; `None` if there was none.
        extension: Option<String>,
    },

    /// The file extension does not name a mesh format that can be read.
    #[error("{}: {}; liemesh reads meshes from files ending in .ply or .obj (letter case does not matter)", show(.path), describe_extension(.extension.as_deref()))]
    UnreadableExtension {
        /// The path whose extension was looked at.
        path: PathBuf,
        /// The extension found, without the dot; `None` if there was none.
        extension: Option<String>,
    },

    /// The format can be written but not read.
    #[error("{}: reading {format} files is not supported; liemesh reads .ply and .obj meshes, so export the mesh in one of those formats instead", show(.path))]
    ReadUnsupported {
        /// The file asked for.
        path: PathBuf,
        /// Its format.
        format: MeshFormat,
    },

    /// The file content does not follow the format.
    #[error("{}: {location}: {message}", show(.path))]
    Parse {
        /// The file being read.
        path: PathBuf,
        /// Where the problem is.
        location: Location,
        /// What is wrong and, where it helps, what to do.
        message: String,
    },

    /// The file ends before all the data its header announces.
    #[error("{}: {location}: the file ends too early: {message}; it was probably cut off while being written or copied, so write or copy it again", show(.path))]
    Truncated {
        /// The file being read.
        path: PathBuf,
        /// The element or line that could not be read completely.
        location: Location,
        /// What was expected.
        message: String,
    },

    /// A face refers to a vertex that does not exist.
    #[error("{}: {location}: vertex index {index} is out of range: {}", show(.path), index_rule(*.format, *.vertex_count))]
    IndexOutOfRange {
        /// The file being read.
        path: PathBuf,
        /// The face (or line) with the bad index.
        location: Location,
        /// The index as written in the file.
        index: i64,
        /// How many vertices were available to it.
        vertex_count: u64,
        /// The file format, which fixes how indices count.
        format: MeshFormat,
    },

    /// A coordinate or other real value is NaN or infinite.
    #[error("{}: {location}: {what} is {value}, but mesh values must be finite numbers; the file is damaged or was written by a tool that failed", show(.path))]
    NonFinite {
        /// The file being read.
        path: PathBuf,
        /// Where the value is.
        location: Location,
        /// Which value, e.g. `property 'x'` or `vertex coordinate 2`.
        what: String,
        /// The value itself.
        value: f64,
    },

    /// The mesh handed to a writer breaks the [`Mesh`] invariants.
    #[error("cannot write the mesh to {}: {reason}; this is a bug in the code that built the mesh", show(.path))]
    InvalidMesh {
        /// The file that was to be written (empty for stream writers).
        path: PathBuf,
        /// Which invariant is broken, and where.
        reason: String,
    },
}

impl IoError {
    /// The file the error is about; empty for errors from the stream
    /// functions that were not given a path.
    pub fn path(&self) -> &Path {
        match self {
            IoError::Io { path, .. }
            | IoError::UnsupportedExtension { path, .. }
            | IoError::UnreadableExtension { path, .. }
            | IoError::ReadUnsupported { path, .. }
            | IoError::Parse { path, .. }
            | IoError::Truncated { path, .. }
            | IoError::IndexOutOfRange { path, .. }
            | IoError::NonFinite { path, .. }
            | IoError::InvalidMesh { path, .. } => path,
        }
    }

    /// Sets the file the error is about (used by [`read_mesh`] and
    /// [`write_mesh`] on errors from the stream functions).
    pub(crate) fn with_path(mut self, new_path: &Path) -> Self {
        match &mut self {
            IoError::Io { path, .. }
            | IoError::UnsupportedExtension { path, .. }
            | IoError::UnreadableExtension { path, .. }
            | IoError::ReadUnsupported { path, .. }
            | IoError::Parse { path, .. }
            | IoError::Truncated { path, .. }
            | IoError::IndexOutOfRange { path, .. }
            | IoError::NonFinite { path, .. }
            | IoError::InvalidMesh { path, .. } => *path = new_path.to_path_buf(),
        }
        self
    }

    /// An I/O error on a stream (no path yet).
    pub(crate) fn stream(source: std::io::Error) -> Self {
        IoError::Io {
            path: PathBuf::new(),
            source,
        }
    }

    /// A parse error on a stream (no path yet).
    pub(crate) fn parse(location: Location, message: impl Into<String>) -> Self {
        IoError::Parse {
            path: PathBuf::new(),
            location,
            message: message.into(),
        }
    }
}

/// Shows a path in messages: quoted, or `<stream>` when empty.
fn show(path: &Path) -> Cow<'static, str> {
    if path.as_os_str().is_empty() {
        Cow::Borrowed("<stream>")
    } else {
        Cow::Owned(format!("'{}'", path.display()))
    }
}

fn describe_extension(extension: Option<&str>) -> String {
    match extension {
        Some(e) => format!("the extension '.{e}' is not a mesh format liemesh knows"),
        None => "the file name has no extension, so the mesh format is unknown".to_owned(),
    }
}

fn index_rule(format: MeshFormat, vertex_count: u64) -> String {
    match format {
        MeshFormat::Obj => format!(
            "{vertex_count} vertices are defined before this line, and OBJ indices count from 1 \
             (negative ones back from the last of them)"
        ),
        _ => format!(
            "the file has {vertex_count} vertices, and PLY indices count from 0, so they must \
             be below {vertex_count}"
        ),
    }
}

/// Writes `mesh` to `path` in the format given by its extension, creating
/// missing parent directories. An existing file is replaced; PLY is written
/// binary unless `options.ply_ascii` is set. The file is written in place, so
/// if writing fails part-way (disk full, say) a partial file is left behind.
///
/// # Errors
///
/// [`IoError::UnsupportedExtension`] for an unknown extension,
/// [`IoError::InvalidMesh`] if the mesh breaks its invariants (nothing is
/// written then), and [`IoError::Io`] if a directory or the file cannot be
/// created or written.
pub fn write_mesh(mesh: &Mesh, path: &Path, options: &WriteOptions) -> Result<(), IoError> {
    let format = MeshFormat::from_path(path)?;
    check_mesh(mesh).map_err(|e| e.with_path(path))?;
    let io_error = |source| IoError::Io {
        path: path.to_path_buf(),
        source,
    };
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        fs::create_dir_all(parent).map_err(|source| IoError::Io {
            path: parent.to_path_buf(),
            source,
        })?;
    }
    let mut w = BufWriter::new(File::create(path).map_err(io_error)?);
    match format {
        MeshFormat::Ply => {
            let encoding = if options.ply_ascii {
                PlyEncoding::Ascii
            } else {
                PlyEncoding::BinaryLittleEndian
            };
            write_ply(mesh, &mut w, encoding)
        }
        MeshFormat::Obj => write_obj(mesh, &mut w),
        MeshFormat::Stl => write_stl(mesh, &mut w),
    }
    .map_err(|e| e.with_path(path))?;
    // Flush explicitly: dropping a BufWriter would swallow the error.
    w.flush().map_err(io_error)
}

/// Reads a PLY or OBJ mesh from `path`, choosing the reader by extension.
///
/// Values missing from the file are filled in: zero normals, and
/// provenance `Provenance { curve: 0, step: 0, s: 0.0, theta: 0.0 }`
/// (OBJ files never carry provenance). Polygons are split into triangle fans.
///
/// # Errors
///
/// [`IoError::UnreadableExtension`] or [`IoError::ReadUnsupported`] (STL)
/// for the path, [`IoError::Io`] if the file cannot be opened or read, and
/// [`IoError::Parse`], [`IoError::Truncated`], [`IoError::IndexOutOfRange`]
/// or [`IoError::NonFinite`] for bad content.
pub fn read_mesh(path: &Path) -> Result<Mesh, IoError> {
    // The formats read are fewer than those written: an unknown extension names those.
    let format = MeshFormat::from_path(path).map_err(|e| match e {
        IoError::UnsupportedExtension { path, extension } => {
            IoError::UnreadableExtension { path, extension }
        }
        e => e,
    })?;
    if format == MeshFormat::Stl {
        return Err(IoError::ReadUnsupported {
            path: path.to_path_buf(),
            format,
        });
    }
    let file = File::open(path).map_err(|source| IoError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let reader = BufReader::new(file);
    match format {
        MeshFormat::Ply => read_ply(reader),
        MeshFormat::Obj => read_obj(reader),
        MeshFormat::Stl => unreachable!("STL was rejected above"),
    }
    .map_err(|e| e.with_path(path))
}

/// Checks the [`Mesh`] invariants the writers rely on: equal vector lengths,
/// triangle indices in range, and finite positions, normals and provenance.
pub(crate) fn check_mesh(mesh: &Mesh) -> Result<(), IoError> {
    let invalid = |reason: String| IoError::InvalidMesh {
        path: PathBuf::new(),
        reason,
    };
    let n = mesh.vertices.len();
    if mesh.normals.len() != n || mesh.provenance.len() != n {
        return Err(invalid(format!(
            "it has {n} vertices but {} normals and {} provenance entries (all three must be equal)",
            mesh.normals.len(),
            mesh.provenance.len()
        )));
    }
    for (i, t) in mesh.triangles.iter().enumerate() {
        if let Some(&bad) = t.iter().find(|&&v| v as usize >= n) {
            return Err(invalid(format!(
                "triangle {i} refers to vertex {bad}, but there are only {n} vertices"
            )));
        }
    }
    for (i, ((p, nrm), prov)) in mesh
        .vertices
        .iter()
        .zip(&mesh.normals)
        .zip(&mesh.provenance)
        .enumerate()
    {
        let values = [
            ("x", p[0]),
            ("y", p[1]),
            ("z", p[2]),
            ("normal x", nrm[0]),
            ("normal y", nrm[1]),
            ("normal z", nrm[2]),
            ("provenance s", prov.s),
            ("provenance theta", prov.theta),
        ];
        if let Some((name, value)) = values.iter().find(|(_, v)| !v.is_finite()) {
            return Err(invalid(format!(
                "vertex {i} has {name} = {value}; files may only hold finite values"
            )));
        }
    }
    Ok(())
}

/// Longest line the text readers accept (1 MiB): bounds memory on garbage input.
pub(crate) const MAX_LINE_BYTES: u64 = 1 << 20;

/// Upper bound on capacity reserved from counts declared in a file, so a
/// lying header cannot make the reader allocate more than the data it holds.
pub(crate) const MAX_PREALLOCATION: usize = 1 << 16;

/// Reads one line (up to and excluding `\n`, with a trailing `\r` removed)
/// into `buf`. Returns `Ok(false)` at end of input.
///
/// Lines longer than [`MAX_LINE_BYTES`] give a parse error at `line_number`.
pub(crate) fn read_line<R: BufRead>(
    reader: &mut R,
    buf: &mut Vec<u8>,
    line_number: u64,
) -> Result<bool, IoError> {
    buf.clear();
    let n = reader
        .by_ref()
        .take(MAX_LINE_BYTES + 1)
        .read_until(b'\n', buf)
        .map_err(IoError::stream)?;
    if n == 0 {
        return Ok(false);
    }
    if buf.last() == Some(&b'\n') {
        buf.pop();
    } else if n as u64 > MAX_LINE_BYTES {
        return Err(IoError::parse(
            Location::Line(line_number),
            format!("the line is longer than {MAX_LINE_BYTES} bytes; this is not a text mesh file"),
        ));
    }
    if buf.last() == Some(&b'\r') {
        buf.pop();
    }
    Ok(true)
}

/// Interprets a line as UTF-8, or gives a parse error at `line_number`.
pub(crate) fn line_str(buf: &[u8], line_number: u64) -> Result<&str, IoError> {
    std::str::from_utf8(buf).map_err(|_| {
        IoError::parse(
            Location::Line(line_number),
            "the line is not valid UTF-8 text; is this a binary file with the wrong extension?",
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::triangulate::Provenance;
    use proptest::prelude::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// A fresh directory under the system temp dir, removed on drop.
    struct TempDir(PathBuf);

    impl TempDir {
        fn new() -> Self {
            static COUNTER: AtomicUsize = AtomicUsize::new(0);
            let dir = std::env::temp_dir().join(format!(
                "liemesh-io-test-{}-{}",
                std::process::id(),
                COUNTER.fetch_add(1, Ordering::Relaxed)
            ));
            fs::create_dir_all(&dir).unwrap();
            TempDir(dir)
        }
    }

    impl Drop for TempDir {
        fn drop(&mut self) {
            let _ = fs::remove_dir_all(&self.0);
        }
    }

    pub(crate) fn sample_mesh() -> Mesh {
        Mesh {
            vertices: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.1],
                [1.0, 1.0, -0.0],
            ],
            normals: vec![[0.0, 0.0, 1.0]; 4],
            triangles: vec![[0, 1, 2], [1, 3, 2]],
            provenance: vec![
                Provenance {
                    curve: 0,
                    step: 0,
                    s: 0.0,
                    theta: 0.0,
                },
                Provenance {
                    curve: 1,
                    step: 3,
                    s: 0.25,
                    theta: 1.5,
                },
                Provenance {
                    curve: 2,
                    step: 7,
                    s: 1.0 / 3.0,
                    theta: -2.0,
                },
                Provenance {
                    curve: Provenance::CLOSING_CURVE,
                    step: 0,
                    s: 2.0,
                    theta: 0.5,
                },
            ],
        }
    }

    pub(crate) fn finite() -> impl Strategy<Value = f64> {
        any::<f64>().prop_filter("finite", |x| x.is_finite())
    }

    pub(crate) fn arb_mesh() -> impl Strategy<Value = Mesh> {
        (0usize..12).prop_flat_map(|n| {
            let v3 = || prop::collection::vec([finite(), finite(), finite()], n);
            let prov = prop::collection::vec(
                (any::<u32>(), any::<u32>(), finite(), finite()).prop_map(
                    |(curve, step, s, theta)| Provenance {
                        curve,
                        step,
                        s,
                        theta,
                    },
                ),
                n,
            );
            let tris = if n == 0 {
                Just(Vec::new()).boxed()
            } else {
                let i = 0..n as u32;
                prop::collection::vec([i.clone(), i.clone(), i], 0..20).boxed()
            };
            (v3(), v3(), tris, prov).prop_map(|(vertices, normals, triangles, provenance)| Mesh {
                vertices,
                normals,
                triangles,
                provenance,
            })
        })
    }

    #[test]
    fn format_is_chosen_by_extension_in_any_case() {
        assert_eq!(
            MeshFormat::from_path(Path::new("a/b.ply")).unwrap(),
            MeshFormat::Ply
        );
        assert_eq!(
            MeshFormat::from_path(Path::new("B.PLY")).unwrap(),
            MeshFormat::Ply
        );
        assert_eq!(
            MeshFormat::from_path(Path::new("x.Obj")).unwrap(),
            MeshFormat::Obj
        );
        assert_eq!(
            MeshFormat::from_path(Path::new("x.stL")).unwrap(),
            MeshFormat::Stl
        );
    }

    #[test]
    fn unsupported_extension_lists_the_supported_ones() {
        let err = MeshFormat::from_path(Path::new("mesh.off")).unwrap_err();
        assert!(
            matches!(&err, IoError::UnsupportedExtension { extension: Some(e), .. } if e == "off")
        );
        let msg = err.to_string();
        assert!(msg.contains("'mesh.off'") && msg.contains(".off"), "{msg}");
        assert!(
            msg.contains(".ply") && msg.contains(".obj") && msg.contains(".stl"),
            "{msg}"
        );

        let err = MeshFormat::from_path(Path::new("mesh")).unwrap_err();
        assert!(matches!(
            err,
            IoError::UnsupportedExtension {
                extension: None,
                ..
            }
        ));
        assert!(err.to_string().contains("no extension"));
    }

    /// Reading names only the formats it reads (it said ".ply, .obj or .stl", and then
    /// refused STL).
    #[test]
    fn reading_an_unknown_extension_lists_the_formats_read() {
        let err = read_mesh(Path::new("invariant.toml")).unwrap_err();
        assert!(
            matches!(&err, IoError::UnreadableExtension { extension: Some(e), .. } if e == "toml")
        );
        let msg = err.to_string();
        assert!(
            msg.contains(".ply") && msg.contains(".obj") && !msg.contains(".stl"),
            "{msg}"
        );
    }

    #[test]
    fn write_mesh_creates_parent_directories_and_read_mesh_reads_it_back() {
        let dir = TempDir::new();
        let mesh = sample_mesh();
        for (name, ascii) in [("a/b/m.ply", false), ("c/m.PLY", true), ("d/m.obj", false)] {
            let path = dir.0.join(name);
            write_mesh(&mesh, &path, &WriteOptions { ply_ascii: ascii }).unwrap();
            let back = read_mesh(&path).unwrap();
            assert_eq!(back.vertices, mesh.vertices, "{name}");
            assert_eq!(back.normals, mesh.normals, "{name}");
            assert_eq!(back.triangles, mesh.triangles, "{name}");
        }
        let stl = dir.0.join("e/m.stl");
        write_mesh(&mesh, &stl, &WriteOptions::default()).unwrap();
        assert_eq!(fs::metadata(&stl).unwrap().len(), 84 + 50 * 2);
    }

    #[test]
    fn written_files_are_identical_for_the_same_mesh() {
        let dir = TempDir::new();
        let mesh = sample_mesh();
        for name in ["m.ply", "m.obj", "m.stl"] {
            let a = dir.0.join(format!("a-{name}"));
            let b = dir.0.join(format!("b-{name}"));
            write_mesh(&mesh, &a, &WriteOptions::default()).unwrap();
            write_mesh(&mesh, &b, &WriteOptions::default()).unwrap();
            assert_eq!(fs::read(&a).unwrap(), fs::read(&b).unwrap(), "{name}");
        }
    }

    #[test]
    fn reading_stl_is_refused_with_a_hint() {
        let err = read_mesh(Path::new("whatever.stl")).unwrap_err();
        assert!(matches!(
            err,
            IoError::ReadUnsupported {
                format: MeshFormat::Stl,
                ..
            }
        ));
        assert!(err.to_string().contains(".ply and .obj"));
    }

    #[test]
    fn missing_file_is_an_io_error_naming_the_path() {
        let dir = TempDir::new();
        let path = dir.0.join("absent.ply");
        let err = read_mesh(&path).unwrap_err();
        assert!(matches!(&err, IoError::Io { path: p, .. } if *p == path));
        assert!(err.to_string().contains("absent.ply"));
    }

    #[test]
    fn parse_errors_from_read_mesh_name_the_file() {
        let dir = TempDir::new();
        let path = dir.0.join("bad.obj");
        fs::write(&path, "v 0 0 0\nv 1 0 zero\n").unwrap();
        let err = read_mesh(&path).unwrap_err();
        assert_eq!(err.path(), path);
        let msg = err.to_string();
        assert!(msg.contains("bad.obj") && msg.contains("line 2"), "{msg}");
    }

    #[test]
    fn invalid_meshes_are_not_written() {
        let dir = TempDir::new();
        let path = dir.0.join("m.ply");

        let mut mesh = sample_mesh();
        mesh.normals.pop();
        let err = write_mesh(&mesh, &path, &WriteOptions::default()).unwrap_err();
        assert!(matches!(err, IoError::InvalidMesh { .. }));
        assert!(!path.exists());

        let mut mesh = sample_mesh();
        mesh.triangles.push([0, 1, 4]);
        let err = write_mesh(&mesh, &path, &WriteOptions::default()).unwrap_err();
        assert!(
            err.to_string().contains("triangle 2 refers to vertex 4"),
            "{err}"
        );

        let mut mesh = sample_mesh();
        mesh.vertices[1][2] = f64::NAN;
        let err = write_mesh(&mesh, &path, &WriteOptions::default()).unwrap_err();
        assert!(err.to_string().contains("vertex 1 has z = NaN"), "{err}");
        assert!(!path.exists());
    }

    #[test]
    fn stream_errors_show_stream_instead_of_a_path() {
        let err = IoError::parse(Location::Line(3), "bad");
        assert_eq!(err.to_string(), "<stream>: line 3: bad");
        let err = err.with_path(Path::new("m.obj"));
        assert_eq!(err.to_string(), "'m.obj': line 3: bad");
    }

    #[test]
    fn long_lines_are_rejected_without_reading_them_whole() {
        let data = vec![b'1'; (MAX_LINE_BYTES + 10) as usize];
        let mut buf = Vec::new();
        let err = read_line(&mut &data[..], &mut buf, 1).unwrap_err();
        assert!(err.to_string().contains("longer than"));
        assert!(buf.len() as u64 <= MAX_LINE_BYTES + 1);
    }

    #[test]
    fn read_line_strips_crlf() {
        let mut input: &[u8] = b"a\r\nb\nc";
        let mut buf = Vec::new();
        let mut lines = Vec::new();
        while read_line(&mut input, &mut buf, 0).unwrap() {
            lines.push(String::from_utf8(buf.clone()).unwrap());
        }
        assert_eq!(lines, ["a", "b", "c"]);
    }
}
