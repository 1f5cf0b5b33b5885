//! `liemesh render`.

use super::picture::{render_to_file, ColorBy, RenderOptions, View};
use super::CliError;
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `liemesh render`.
#[derive(Debug, Clone, Args)]
pub struct RenderArgs {
    /// The mesh to draw (.ply or .obj).
    pub mesh: PathBuf,
    /// The picture: .png or .svg.
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
    /// Shared picture options.
    #[command(flatten)]
    pub picture: PictureArgs,
}

/// How to draw a mesh (shared by `render` and `mesh --png`).
#[derive(Debug, Clone, Args)]
pub struct PictureArgs {
    /// Direction the camera looks from, `x,y,z`.
    #[arg(long, value_parser = super::mesh::parse_vec3, allow_hyphen_values = true, default_value = "2,-3,1.6")]
    pub view: [f64; 3],
    /// Perspective projection with this field of view in degrees (orthographic without it).
    #[arg(long)]
    pub perspective: Option<f64>,
    /// Colour faces or edges by a quality measure.
    #[arg(long, value_parser = ["none", "min-angle", "normal-angle"], default_value = "none")]
    pub color_by: String,
    /// Picture width and height in pixels.
    #[arg(long, default_value_t = 800)]
    pub size: u32,
}

impl PictureArgs {
    /// The renderer options these arguments describe.
    pub fn options(&self) -> RenderOptions {
        let up = [0.0, 0.0, 1.0];
        RenderOptions {
            width: self.size,
            height: self.size,
            view: match self.perspective {
                Some(fov) => View::Perspective {
                    direction: self.view,
                    up,
                    fov_degrees: fov,
                },
                None => View::Orthographic {
                    direction: self.view,
                    up,
                },
            },
            color_by: match self.color_by.as_str() {
                "min-angle" => ColorBy::MinAngle,
                "normal-angle" => ColorBy::EdgeNormalAngle,
                _ => ColorBy::None,
            },
            ..RenderOptions::default()
        }
    }
}

pub(super) fn run(args: &RenderArgs) -> Result<ExitCode, CliError> {
    let mesh = liemesh::io::read_mesh(&args.mesh)?;
    render_to_file(&mesh, &args.output, &args.picture.options())?;
    Ok(ExitCode::SUCCESS)
}
