//! What the contact of both solvers shares: the grid of several velocity
//! fields, with shared nodes split per field and the meetings of two fields
//! (`field_split`), and the per-pair totals of contact.csv (`totals`). The
//! contact laws themselves are each solver's: `solver::explicit::contact`
//! (momentum correction at the meetings) and `solver::implicit::terms::contact`
//! (penalty).

pub(crate) mod field_split;
pub(crate) mod totals;
