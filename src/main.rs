//! The `marsupial` command-line tool.

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// Reactive vision-based docking: validate profiles, run perception, docking runs and
/// trial campaigns in the built-in simulator.
#[derive(Parser, Debug)]
#[command(name = "marsupial", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Validate profile and scenario files.
    ///
    /// Prints `ok FILE` for each valid file. For each invalid file prints every problem
    /// as `FILE:LINE: FIELD.PATH: what was expected`, and exits with status 1.
    Check {
        /// Files to check (TOML).
        #[arg(required = true, value_name = "FILE")]
        files: Vec<PathBuf>,
    },
    /// Run the two-block perceptual schema on image files.
    ///
    /// The images are processed in order as a stream, so adaptation carries from one to
    /// the next (and the fallback timeouts run on `--interval` seconds per image). With
    /// `--imprint`, those images are imprinted on first, as on departure from the dock.
    /// PNG and JPEG are read; grey and RGBA images are converted.
    ///
    /// `--json` prints one object per image: image, width, height, found, left_px,
    /// right_px, total_px, ratio, left_centroid, right_centroid, offset_px, mode
    /// (adapted / imprinted / table) and us_per_frame (median over --repeat runs).
    Detect {
        /// Profile with a [fiducial.two_block] (e.g. profiles/bujold.toml).
        #[arg(long, value_name = "PROFILE")]
        profile: PathBuf,
        /// Imprint on this image first (repeatable; several frames are averaged).
        #[arg(long, value_name = "IMAGE")]
        imprint: Vec<PathBuf>,
        /// Static segmentation: keep the imprint, never adapt.
        #[arg(long = "static")]
        static_mode: bool,
        /// One JSON object per image.
        #[arg(long)]
        json: bool,
        /// Write the frame with segmented pixels painted in (PNG); with several images an
        /// index is added: OUT-000.png, OUT-001.png …
        #[arg(long, value_name = "OUT.png")]
        overlay: Option<PathBuf>,
        /// Time the whole schema this many times per image and report the median.
        #[arg(long, value_name = "N", default_value_t = 1)]
        repeat: usize,
        /// Seconds between images (default: one frame period of the profile's camera).
        #[arg(long, value_name = "S")]
        interval: Option<f64>,
        /// Images, in stream order.
        #[arg(required = true, value_name = "IMAGE")]
        images: Vec<PathBuf>,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Check { files } => {
            let bad = marsupial::cli::check::run(&files, &mut std::io::stdout(), &mut std::io::stderr());
            if bad == 0 { ExitCode::SUCCESS } else { ExitCode::FAILURE }
        }
        Command::Detect {
            profile,
            imprint,
            static_mode,
            json,
            overlay,
            repeat,
            interval,
            images,
        } => {
            let opts = marsupial::cli::detect::DetectOptions {
                profile,
                imprint,
                static_mode,
                json,
                overlay,
                repeat,
                interval,
                images,
            };
            match marsupial::cli::detect::run(&opts, &mut std::io::stdout()) {
                Ok(()) => ExitCode::SUCCESS,
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::FAILURE
                }
            }
        }
    }
}
