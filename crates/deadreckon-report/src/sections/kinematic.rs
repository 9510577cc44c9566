//! A kinematic shape's calibration (a tricycle, a differential drive): the
//! shape and why, and one row per parameter with its standard error and
//! status, in place of the car's circumference table.

use crate::model::Kinematic;
use crate::page::{Block, RowView, SectionView, TableView};
use crate::plot::fmt_sig;

/// Renders the section.
pub(crate) fn section(k: &Kinematic) -> SectionView {
    let rows = k
        .params
        .iter()
        .map(|p| RowView {
            swatch: None,
            cells: vec![
                p.name.clone(),
                fmt_sig(p.value, 6),
                p.std.map_or("–".into(), |s| fmt_sig(s, 3)),
                p.status.clone(),
            ],
        })
        .collect();
    let mut blocks = vec![Block::Note {
        text: format!("shape: {}", k.shape),
    }];
    blocks.push(Block::Tables {
        tables: vec![TableView {
            caption: format!(
                "Kinematic calibration against {}: value, standard error and status of each parameter.",
                k.method
            ),
            headers: ["parameter", "value", "std", "status"]
                .map(String::from)
                .to_vec(),
            rows,
            text_column: Some(3),
        }],
    });
    if !k.fit.is_empty() {
        blocks.push(Block::Note {
            text: k.fit.clone(),
        });
    }
    SectionView {
        id: "kinematic",
        title: "Kinematic calibration",
        blocks,
    }
}
