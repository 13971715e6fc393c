//! The time histories of the scene (`scene::curve`): inline tables checked
//! row by row (files are checked as they are read, with their lines).

use super::check::{ensure, Check};
use crate::scene::curve::TimeHistory;
use crate::scene::SceneConfig;

/// The inline tables: at least one row, each `[t, value]` of finite numbers,
/// times strictly increasing. An error names the row (`….time_history.2`).
pub fn time_histories(s: &SceneConfig) -> Check {
    for (key, h) in s.time_histories() {
        let TimeHistory::Table(rows) = h else {
            continue;
        };
        ensure(
            !rows.is_empty(),
            &key,
            "a time history needs at least one [time, value] row",
        )?;
        for (k, row) in rows.iter().enumerate() {
            let at = format!("{key}.{k}");
            ensure(
                row.len() == 2,
                &at,
                format!("a row is [time, value]; this one has {} entries", row.len()),
            )?;
            ensure(
                row.iter().all(|x| x.is_finite()),
                &at,
                "time and value must be finite numbers",
            )?;
            if k > 0 {
                let before = rows[k - 1][0];
                ensure(
                    row[0] > before,
                    &at,
                    format!("time {} does not follow the previous row's {before}: times must increase strictly", row[0]),
                )?;
            }
        }
    }
    Ok(())
}

/// `gravity_history` needs a gravity to scale and takes the place of the
/// stages' ramps (`gravity_ramp_time`, and the quasi-static `gravity_ramp`).
pub fn gravity_history(s: &SceneConfig) -> Check {
    if s.gravity_history.is_none() {
        return Ok(());
    }
    ensure(
        s.gravity.is_some(),
        "gravity_history",
        "scales `gravity`, which the scene does not give",
    )?;
    let prefixes: Vec<String> = match &s.solver {
        Some(_) => vec!["solver".into()],
        None => (0..s.stages.len()).map(|k| format!("stage.{k}")).collect(),
    };
    for (st, prefix) in s.stages().into_iter().zip(prefixes) {
        let what = "a scene with `gravity_history` (gravity follows it in every stage)";
        let why = format!("does not apply to {what}");
        ensure(
            st.gravity_ramp_time.is_none(),
            format!("{prefix}.gravity_ramp_time"),
            &why,
        )?;
        ensure(
            st.gravity_ramp.is_none(),
            format!("{prefix}.gravity_ramp"),
            &why,
        )?;
    }
    Ok(())
}
