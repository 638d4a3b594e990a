//! The occluder file a production render's header names: lookdev's Blender script writes the
//! scene's triangles beside its g-buffer and names them in the render's note, after the camera:
//! `lookdev.camera … occluders=NAME visibility=SIDE` (docs/formats.md#occluders).

use super::camera::note_field;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Triangles to trace a g-buffer's visibility through.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Occluders {
    /// The glTF file (`.glb` or `.gltf`).
    pub file: PathBuf,
    /// The visibility grid's side; `None` for [`crate::visibility::default_side`].
    pub side: Option<u32>,
    /// Where the request came from, for messages: `--occluders`, the header's note.
    pub from: String,
}

/// The occluders the header's note names, with their file relative to `folder` (the g-buffer's).
pub fn from_note(text: &BTreeMap<String, String>, folder: &Path) -> Result<Option<Occluders>, String> {
    let field = |key: &str| note_field(text, key);
    let Some(name) = field("occluders") else { return Ok(None) };
    let name = percent_encoding::percent_decode_str(name)
        .decode_utf8()
        .map_err(|_| format!("the header's note has occluders={name}, not a UTF-8 file name"))?;
    let side = field("visibility")
        .map(|side| {
            side.parse::<u32>().ok().filter(|s| crate::visibility::SIDES.contains(s)).ok_or_else(|| {
                format!("the header's note has visibility={side}, not one of {}", crate::visibility::side_list())
            })
        })
        .transpose()?;
    Ok(Some(Occluders { file: folder.join(&*name), side, from: "the header's note".into() }))
}

#[cfg(test)]
mod tests {
    use super::super::camera::NOTE_ATTRIBUTE;
    use super::*;

    fn note(text: &str) -> BTreeMap<String, String> {
        BTreeMap::from([(NOTE_ATTRIBUTE.to_string(), text.to_string())])
    }

    #[test]
    fn the_note_names_the_occluders_beside_the_gbuffer() {
        let folder = Path::new("shots/a");
        let named = |text: &str| from_note(&note(text), folder);
        let camera = "lookdev.camera position=0,0,0 forward=0,1,0 projection=perspective";
        assert_eq!(named(camera), Ok(None));
        let found = named(&format!("{camera} occluders=shot%20one.occluders.glb visibility=16")).unwrap().unwrap();
        assert_eq!((found.file, found.side), (PathBuf::from("shots/a/shot one.occluders.glb"), Some(16)));
        let found = named(&format!("{camera} occluders=x.glb")).unwrap().unwrap();
        assert_eq!(found.side, None);
        assert!(named(&format!("{camera} occluders=x.glb visibility=20")).unwrap_err().contains("visibility=20"));
        assert!(named(&format!("{camera} occluders=%FF.glb")).unwrap_err().contains("UTF-8"));
        assert_eq!(from_note(&note("someone else's note occluders=x.glb"), folder), Ok(None));
    }
}
