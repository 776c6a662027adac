//! A campaign's results as people read them (feature `sim`): the side-by-side tables
//! against the papers' published figures ([`paper`]), success binned by a drawn
//! parameter ([`bins`], `trials --bin`) and the SVG plots ([`plot`]). The simulator
//! writes run records (`runs.jsonl`, `summary.json`); this layer formats them, for
//! `marsupial trials`, `merge` and `estimate`.

pub mod bins;
pub mod paper;
pub mod plot;
