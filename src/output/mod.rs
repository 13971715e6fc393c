//! Run outputs: energy/centre-of-mass history (`history.csv`), the final particle
//! state (`particles_final.csv`), ParaView frames (`.vtu` + `.pvd`), a terminal
//! progress bar and pretty-printed JSON (`summary.json`); [`Table`] reads the CSV
//! files back by column name.
//!
//! Every writer is generic over the dimension `D` (2 or 3). Floating-point numbers in
//! text files are written with the shortest representation that parses back to the
//! same `f64`: plain notation for moderate magnitudes, scientific (`1e-7`) otherwise.
//! Files written whole (summary.json, particles_final.csv, frames) are replaced
//! atomically (`atomic.rs`).

pub(crate) mod atomic;
pub(crate) mod csv_file;
mod history;
pub mod matrix_market;
mod particles_csv;
mod progress;
mod table;
mod text;
mod vtk;

pub use csv_file::{CsvWriter, Field};
pub use history::{body_centres, HistoryWriter};
pub use particles_csv::{write_particles_csv, write_particles_csv_with};
pub use progress::Progress;
pub use table::Table;
pub use text::write_json;
pub use vtk::FrameWriter;
