//! `hikari lut`: the grading workflow's other half. `extract` reads the grade back from a
//! screenshot written by `hikari render --lut-screenshot` and graded in a photo editor;
//! `apply` grades a PNG with a `.cube` LUT (trilinear, as colour tools do).

use std::path::PathBuf;

use clap::{Args, Subcommand};

use hikari_render::output;
use hikari_render::techniques::tonemap::{cube::CubeLut, lut_strip};

use crate::still::{self, ImageFile};

#[derive(Subcommand, Debug)]
pub enum LutCommand {
    /// Read the grade of a graded `--lut-screenshot` PNG into a `.cube` file.
    Extract(ExtractArgs),
    /// Grade a PNG with a `.cube` LUT.
    Apply(ApplyArgs),
}

#[derive(Args, Debug)]
pub struct ExtractArgs {
    /// The graded screenshot (PNG with its LUT strip at the bottom).
    pub graded: PathBuf,
    /// The `.cube` file to write.
    #[arg(short, long)]
    pub output: PathBuf,
}

#[derive(Args, Debug)]
pub struct ApplyArgs {
    /// The `.cube` LUT.
    pub lut: PathBuf,
    /// The PNG to grade.
    pub input: PathBuf,
    /// The graded PNG to write.
    #[arg(short, long)]
    pub output: PathBuf,
}

pub fn run(command: LutCommand) -> anyhow::Result<()> {
    match command {
        LutCommand::Extract(a) => {
            if !a
                .output
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("cube"))
            {
                anyhow::bail!(
                    "-o {}: this writes an Adobe .cube LUT; give a file name ending in .cube",
                    a.output.display()
                );
            }
            still::check_output_file("-o", &a.output)?;
            let img = lut_strip::read_png(&a.graded)?;
            let lut = lut_strip::extract(&img, &a.graded.display().to_string())?;
            lut.write(&a.output)?;
            println!("wrote {}", a.output.display());
        }
        LutCommand::Apply(a) => {
            still::check_image_file("-o", &a.output, ImageFile::Png)?;
            let lut = CubeLut::read(&a.lut)?;
            let img = lut_strip::read_png(&a.input)?;
            output::write_png(&a.output, &lut_strip::apply(&img, &lut))?;
            println!("wrote {}", a.output.display());
        }
    }
    Ok(())
}
