//! `deadreckon import FORMAT SOURCE --out DIR`: read a log into a drive
//! directory. The options become a `deadreckon_api::import::ImportOptions`,
//! `deadreckon_api::import::import` returns the drive and a printable report;
//! the drive is written atomically (into a
//! temporary sibling directory renamed into place when `--out` is new; file by
//! file when it exists).

use anyhow::Result;
use deadreckon_api::import::{import, Imported};

use crate::args::import::*;

/// Runs an import.
pub fn run(a: ImportArgs, load: &super::common::Loader) -> Result<()> {
    // Before the import's work: an existing drive is not replaced unasked.
    if !a.force {
        let occupied =
            a.out.is_file() || std::fs::read_dir(&a.out).is_ok_and(|mut d| d.next().is_some());
        anyhow::ensure!(
            !occupied,
            "{} exists and is not empty: the import would replace its files (--force replaces them)",
            a.out.display()
        );
    }
    let (format, options) = a.options(load.mapping.clone())?;
    let Imported {
        drive,
        report,
        files,
    } = import(format, &a.source, &options)?;
    deadreckon_api::import::write_with(&a.out, &drive, &files)?;
    outln!("{}", report.trim_end_matches('\n'));
    outln!("{}", deadreckon_api::import::counts_line(&drive));
    outln!("wrote {}", a.out.display());
    Ok(())
}
