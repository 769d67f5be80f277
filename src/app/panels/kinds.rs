//! The panels that belong to one kind of object, registered by kind: the editor shows, under
//! *Selected object*, every panel registered for the selected object's kind
//! ([`crate::scene::ObjectKind::kind_name`]). A built-in kind's panel is one entry of
//! [`BUILT_IN`]; a kind defined elsewhere (a plug-in, a test) adds its own with [`register`],
//! beside its [`crate::scene::registry::register`], and nothing else in the editor changes.

use std::sync::{PoisonError, RwLock};

use eframe::egui;

use crate::app::KnotworkApp;

/// Draws a kind's panel for the selected object (its index).
pub type ShowPanel = fn(&mut KnotworkApp, &mut egui::Ui, usize);

/// One kind's panel, as registered.
#[derive(Clone, Copy)]
pub struct KindPanel {
    /// The kinds it serves, by [`crate::scene::ObjectKind::kind_name`].
    pub kinds: &'static [&'static str],
    pub show: ShowPanel,
}

/// The built-in kinds' panels.
pub const BUILT_IN: [KindPanel; 4] = [
    KindPanel {
        kinds: &["a NURBS surface", "a trimmed NURBS surface"],
        show: |app, ui, s| app.knots_and_degree(ui, s),
    },
    KindPanel {
        kinds: &[
            "a NURBS surface",
            "a trimmed NURBS surface",
            "a polysurface",
        ],
        show: |app, ui, s| app.mass_panel(ui, s),
    },
    KindPanel {
        kinds: &["a subdivision surface", "a polygon mesh"],
        show: |app, ui, _| app.subdivision_panel(ui),
    },
    KindPanel {
        kinds: &["a triangular Bézier patch"],
        show: |app, ui, _| app.triangle_panel(ui),
    },
];

/// Panels registered while the program runs.
static REGISTERED: RwLock<Vec<KindPanel>> = RwLock::new(Vec::new());

/// Adds a panel for the kinds it names (shown after any panel already registered for them).
pub fn register(panel: KindPanel) {
    REGISTERED
        .write()
        .unwrap_or_else(PoisonError::into_inner)
        .push(panel);
}

/// The panels for objects of kind `kind_name`, built-in ones first.
pub fn panels_for(kind_name: &str) -> Vec<ShowPanel> {
    let registered = REGISTERED.read().unwrap_or_else(PoisonError::into_inner);
    BUILT_IN
        .iter()
        .chain(registered.iter())
        .filter(|p| p.kinds.contains(&kind_name))
        .map(|p| p.show)
        .collect()
}

impl KnotworkApp {
    /// The selected object's kind panels ([`panels_for`]).
    pub(in crate::app) fn kind_panels(&mut self, ui: &mut egui::Ui) {
        let Some(s) = self.selection.object else {
            return;
        };
        let Some(object) = self.scene().objects.get(s) else {
            return;
        };
        for show in panels_for(object.kind().kind_name()) {
            show(self, ui, s);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every built-in kind with a panel names a kind the registry knows, by the name its
    /// examples give.
    #[test]
    fn the_built_in_panels_serve_registered_kinds() {
        let names: Vec<&str> = crate::scene::registry::kinds()
            .iter()
            .flat_map(|k| (k.examples)())
            .map(|o| o.kind().kind_name())
            .collect();
        for panel in BUILT_IN {
            for kind in panel.kinds {
                assert!(
                    names.contains(kind),
                    "{kind} is not a registered kind: {names:?}"
                );
            }
        }
        assert_eq!(panels_for("a triangular Bézier patch").len(), 1);
        assert!(panels_for("a NURBS curve").is_empty());
    }
}
