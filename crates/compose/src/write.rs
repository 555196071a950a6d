//! The write phase: the composite tagged with the passes' space (EXR) or converted to linear
//! Rec.709 for the standard view (PNG), written by glassdb-encode.

use glassdb_encode::{OutputFormat, WrittenOutput};

use crate::colour::SpaceSource;
use crate::composite::ToWrite;
use crate::{ComposeError, ComposeJob, ComposeSettings, FrameColour};

/// The write phase: the composite tagged with the passes' space (EXR) or converted to linear
/// Rec.709 for the standard view (PNG), written by glassdb-encode.
pub(crate) fn write(
    job: &ComposeJob,
    image: ToWrite,
    settings: &ComposeSettings,
) -> Result<(WrittenOutput, FrameColour), ComposeError> {
    let ToWrite {
        mut trans,
        mut frame,
        space,
        table,
    } = image;
    if space.source != SpaceSource::Untagged {
        frame.tag_space = Some(space.space);
    }
    let format = glassdb_encode::output_format(&job.output)?;
    let converted_for_display = format == OutputFormat::Png
        && matches!(
            settings.output.view,
            None | Some(glassdb_colour::DisplayView::Standard)
        )
        && space.space != glassdb_colour::RgbSpace::Srgb;
    if converted_for_display {
        trans.image.convert_rgb(glassdb_colour::rgb_to_rgb(
            space.space,
            glassdb_colour::RgbSpace::Srgb,
        ));
    }
    // The folders `-o` names are made now, once the frame has composited (a failed frame
    // makes none).
    glassdb_io::create_output_dirs(&job.output)?;
    let output = glassdb_encode::write_output(
        &job.output,
        trans.image,
        frame,
        &trans.source,
        &settings.output,
    )?;
    let colour = FrameColour {
        space,
        table,
        converted_for_display,
    };
    Ok((output, colour))
}
