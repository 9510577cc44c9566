//! TedriS models read from files, for the command line and the Python
//! bindings.

use std::path::Path;

use deadreckon_tedris::TedrisModel;

use crate::Error;

/// The model in the JSON file `path` (`tedris train --out`), checked:
/// errors name the file.
pub fn read_model(path: &Path) -> Result<TedrisModel, Error> {
    let text = std::fs::read_to_string(path).map_err(|source| Error::ModelFile {
        path: path.to_path_buf(),
        source,
    })?;
    TedrisModel::from_json(&text).map_err(|source| Error::Model {
        path: path.to_path_buf(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_report_and_compare_loaded_a_model_without_checking_it() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("m.json");
        let e = read_model(&p).unwrap_err();
        assert!(e.to_string().contains("m.json"), "{e}");
        std::fs::write(&p, "{").unwrap();
        let e = crate::chain_text(&read_model(&p).unwrap_err());
        assert!(e.contains("m.json") && e.contains("JSON"), "{e}");
    }
}
