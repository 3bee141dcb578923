//! The reference image of the RMSE plot and the difference view: chosen
//! by hand, frozen from a view, or found beside the scene file.

use super::ViewerApp;
use crate::image::Image;
use std::path::Path;
use std::sync::Arc;

impl ViewerApp {
    /// The reference file found beside the scene, if that is the one in use.
    pub fn reference_beside_scene(&self) -> Option<&Path> {
        self.reference_beside.as_deref()
    }

    /// A reference beside the scene file (`reference.exr`, or the
    /// `TungstenRender.exr` that Bitterli's scenes ship) is loaded with
    /// the scene, as a renderer's test scene is meant to be compared,
    /// unless a reference was chosen by hand; it is not remembered in the
    /// settings.
    pub(super) fn pick_reference_beside(&mut self, scene: &Path) {
        if self.reference.is_some() && self.reference_beside.is_none() {
            return;
        }
        let dir = scene.parent().unwrap_or(Path::new("."));
        let found = ["reference.exr", "TungstenRender.exr"]
            .into_iter()
            .map(|name| dir.join(name))
            .find(|p| p.is_file());
        self.reference = None;
        self.reference_beside = None;
        self.live.set_reference(None);
        let Some(path) = found else {
            return;
        };
        match Image::read(&path) {
            Ok(image) => {
                self.toast(format!(
                    "reference {} ({}x{}, found beside the scene): true RMSE where the image is a whole multiple of its size",
                    path.display(),
                    image.width,
                    image.height
                ));
                let image = Arc::new(image);
                self.reference = Some(image.clone());
                self.reference_beside = Some(path);
                self.live.set_reference(Some(image));
            }
            Err(e) => self.toast(format!("reference beside the scene not read: {e}")),
        }
    }

    /// Loads a reference image for RMSE and the difference view.
    pub fn load_reference(&mut self, path: &str) {
        if path.is_empty() {
            self.reference = None;
            self.settings.reference_path.clear();
            self.live.set_reference(None);
            return;
        }
        match Image::read(Path::new(path)) {
            Ok(image) => {
                let image = Arc::new(image);
                self.reference = Some(image.clone());
                self.reference_beside = None;
                self.live.set_reference(Some(image));
                self.settings.reference_path = path.to_string();
            }
            Err(e) => {
                self.reference = None;
                self.errors.push(e.to_string());
            }
        }
    }

    /// Freezes view `index`'s current image as the reference (a long
    /// tracelab render serves as well as an external one).
    pub fn use_view_as_reference(&mut self, index: usize) {
        let frame = self.live.latest();
        if let Some(view) = frame.views.get(index) {
            let reference = Arc::new(view.snapshot.image.clone());
            self.reference = Some(reference.clone());
            self.reference_beside = None;
            self.live.set_reference(Some(reference));
            self.settings.reference_path.clear();
            self.toast(format!(
                "reference: image {} at {} spp (from now on; render with another seed for an independent estimate)",
                if index == 0 { "A" } else { "B" },
                view.stats.spp
            ));
        }
    }

    pub fn reference(&self) -> Option<&Arc<Image>> {
        self.reference.as_ref()
    }
}
