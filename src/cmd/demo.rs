//! `deadreckon demo`: the whole four-wheel method and TedriS on simulated
//! drives ([`deadreckon_api::demo`]), printed as tables or JSON.

use anyhow::Result;

use super::common;
use crate::args::demo::DemoArgs;

/// Runs `demo`.
pub fn run(a: DemoArgs, quiet: bool, load: &common::Loader) -> Result<()> {
    let steps = super::progress::Steps::new(16, quiet);
    let demo = deadreckon_api::demo::run(&a.out, a.seed, load, &steps, &common::footer())?;
    steps.finish();
    if a.json {
        common::print_pretty(&demo.json())
    } else {
        common::print_lines(demo.lines())
    }
}
