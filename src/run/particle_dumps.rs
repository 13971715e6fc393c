//! Particle files at chosen times (`[output] particle_times`, `particle_interval`):
//! `particles_NNNN.csv`, with the columns of particles_final.csv, at the step
//! nearest each time (`run::schedule`), and `particle_times.csv`
//! (`file,t,step`) saying which time each file holds.

use crate::model::Model;
use crate::output::{write_particles_csv_with, CsvWriter, Field};
use crate::run::schedule::Schedule;
use crate::scene::OutputConfig;
use serde::{Deserialize, Serialize};
use std::io;
use std::path::{Path, PathBuf};

/// The columns of particle_times.csv.
const COLUMNS: [&str; 3] = ["file", "t", "step"];

/// The particle files of a run, and when the next is due.
pub struct ParticleDumps {
    dir: PathBuf,
    times: Schedule,
    index: CsvWriter,
    written: usize,
    /// Time of the last file (a state is written once, for every time it is
    /// the nearest to).
    last: Option<f64>,
}

/// Where the particle files are, for a checkpoint.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DumpState {
    pub index_csv: String,
    pub written: usize,
    /// The next time not yet taken (none: all were).
    pub next: Option<f64>,
}

impl ParticleDumps {
    /// The dumps `output` asks for in a run of `end_time`, into `dir` (none
    /// when it asks for none).
    pub fn create(dir: &Path, output: &OutputConfig, end_time: f64) -> io::Result<Option<Self>> {
        let Some(times) = schedule(output, end_time) else {
            return Ok(None);
        };
        Ok(Some(ParticleDumps {
            dir: dir.to_path_buf(),
            times,
            index: CsvWriter::create(&dir.join("particle_times.csv"), &COLUMNS)?,
            written: 0,
            last: None,
        }))
    }

    /// Continue the dumps of a checkpoint's `saved` state, the files written
    /// so far copied from `from` (the checkpoint's directory) when it is
    /// another directory and they are there.
    pub fn resume(&mut self, saved: &DumpState, from: Option<&Path>) -> io::Result<()> {
        for name in (0..saved.written).map(file_name) {
            let source = from.map(|dir| dir.join(&name));
            if let Some(source) = source.filter(|s| s.exists()) {
                crate::output::atomic::replace(&self.dir.join(&name), |tmp| {
                    std::fs::copy(&source, tmp).map(|_| ())
                })?;
            }
        }
        self.index = CsvWriter::resume(&self.dir.join("particle_times.csv"), &saved.index_csv)?;
        self.written = saved.written;
        match saved.next {
            Some(next) => self.times.resume_at(next),
            None => self.times.resume_at(f64::INFINITY),
        }
        Ok(())
    }

    /// The state to save in a checkpoint.
    pub fn saved(&mut self) -> io::Result<DumpState> {
        self.index.flush()?;
        Ok(DumpState {
            index_csv: std::fs::read_to_string(self.dir.join("particle_times.csv"))?,
            written: self.written,
            next: self.times.next_time(),
        })
    }

    /// The particle file of the state at `t` (step `step`) when it is the
    /// nearest to a time of the list (`Schedule::take`).
    pub fn at<const D: usize>(
        &mut self,
        m: &Model<D>,
        t: f64,
        step: usize,
        next_dt: Option<f64>,
        tolerance: f64,
    ) -> io::Result<()> {
        if !self.times.take(t, next_dt, tolerance) || self.last == Some(t) {
            return Ok(());
        }
        self.last = Some(t);
        let name = file_name(self.written);
        let fields = m.point_fields();
        let extra: Vec<(&str, &[f64])> = (fields.iter()).map(|(n, v)| (*n, v.as_slice())).collect();
        write_particles_csv_with(&self.dir.join(&name), &m.output_particles(), &extra)?;
        self.written += 1;
        self.index
            .row([Field::Text(&name), t.into(), Field::from(step)])?;
        self.index.flush()
    }
}

/// The k-th particle file.
fn file_name(k: usize) -> String {
    format!("particles_{k:04}.csv")
}

/// The times of `particle_times` and `particle_interval` together (k × interval
/// up to `end_time`).
fn schedule(output: &OutputConfig, end_time: f64) -> Option<Schedule> {
    match (&output.particle_times, output.particle_interval) {
        (None, None) => None,
        (times, None) => Some(Schedule::list(times.clone().unwrap_or_default())),
        (None, Some(interval)) => Some(Schedule::interval(interval)),
        (Some(times), Some(interval)) => {
            let steps = (end_time / interval * (1.0 + 1e-12)).floor() as usize;
            let every = (0..=steps).map(|k| k as f64 * interval);
            Some(Schedule::list(times.iter().copied().chain(every).collect()))
        }
    }
}
