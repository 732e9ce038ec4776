//! The tables of a run: `steps.csv`, `cycles.csv` and the field files, each defined once as
//! named columns ([`Table`]) that the CSV writer and the Python package both read. Headers carry
//! the units; numbers are written as `%.10e`, counters as integers, a missing value as an empty
//! field.

use crate::analysis::CycleRow;
use crate::contact::SurfacePoint;
use crate::history::StepRecord;

/// One column's values.
#[derive(Debug, Clone, PartialEq)]
pub enum Column {
    /// Real numbers.
    Real(Vec<f64>),
    /// Real numbers that may be missing.
    MaybeReal(Vec<Option<f64>>),
    /// Counters.
    Count(Vec<usize>),
    /// Counters that may be missing.
    MaybeCount(Vec<Option<usize>>),
    /// Labels.
    Text(Vec<String>),
}

impl Column {
    fn len(&self) -> usize {
        match self {
            Column::Real(v) => v.len(),
            Column::MaybeReal(v) => v.len(),
            Column::Count(v) => v.len(),
            Column::MaybeCount(v) => v.len(),
            Column::Text(v) => v.len(),
        }
    }

    fn cell(&self, row: usize) -> String {
        let real = |x: f64| format!("{x:.10e}");
        match self {
            Column::Real(v) => real(v[row]),
            Column::MaybeReal(v) => v[row].map(real).unwrap_or_default(),
            Column::Count(v) => v[row].to_string(),
            Column::MaybeCount(v) => v[row].map(|k| k.to_string()).unwrap_or_default(),
            Column::Text(v) => v[row].clone(),
        }
    }
}

/// Named columns of equal length.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// `(name with unit, values)` in file order.
    pub columns: Vec<(&'static str, Column)>,
}

impl Table {
    /// The number of rows.
    pub fn rows(&self) -> usize {
        self.columns.first().map_or(0, |(_, c)| c.len())
    }

    /// The table as CSV with a header line.
    pub fn csv(&self) -> Vec<u8> {
        let mut w = csv::Writer::from_writer(Vec::new());
        self.write_header(&mut w).expect("in-memory write");
        self.write_rows(&mut w).expect("in-memory write");
        w.into_inner().expect("in-memory write")
    }

    fn write_header<W: std::io::Write>(&self, w: &mut csv::Writer<W>) -> csv::Result<()> {
        w.write_record(self.columns.iter().map(|(name, _)| *name))
    }

    fn write_rows<W: std::io::Write>(&self, w: &mut csv::Writer<W>) -> csv::Result<()> {
        for row in 0..self.rows() {
            w.write_record(self.columns.iter().map(|(_, c)| c.cell(row)))?;
        }
        Ok(())
    }
}

/// Records per block of [`write_steps_csv`].
const STEPS_BLOCK: usize = 4096;

/// `steps.csv` written as the records arrive, a block of [`STEPS_BLOCK`] records at a time:
/// the header when made, the rows of each block when it fills, the rest at
/// [`StepsCsv::finish`]: the bytes of [`steps_table`]`(records, friction).csv()`. A long history
/// has hundreds of thousands of steps; this holds a block of them.
pub(crate) struct StepsCsv<W: std::io::Write> {
    writer: csv::Writer<W>,
    block: Vec<StepRecord>,
    friction: f64,
    bulk: bool,
}

impl<W: std::io::Write> StepsCsv<W> {
    /// Write the header to `out`; `friction` is η, `bulk` whether the history has a bulk
    /// stress (the column `bulk_stress_Pa`).
    pub(crate) fn new(out: W, friction: f64, bulk: bool) -> std::io::Result<Self> {
        let mut writer = csv::Writer::from_writer(out);
        steps_table_of(&[], friction, bulk).write_header(&mut writer)?;
        Ok(Self {
            writer,
            block: Vec::with_capacity(STEPS_BLOCK),
            friction,
            bulk,
        })
    }

    /// Take the next record.
    pub(crate) fn push(&mut self, record: &StepRecord) -> std::io::Result<()> {
        self.block.push(record.clone());
        if self.block.len() == STEPS_BLOCK {
            self.write_block()?;
        }
        Ok(())
    }

    fn write_block(&mut self) -> std::io::Result<()> {
        steps_table_of(&self.block, self.friction, self.bulk).write_rows(&mut self.writer)?;
        self.block.clear();
        Ok(())
    }

    /// Write the rows not yet written and flush; the writer.
    pub(crate) fn finish(mut self) -> std::io::Result<W> {
        self.write_block()?;
        self.writer.flush()?;
        self.writer
            .into_inner()
            .map_err(|e| std::io::Error::other(e.to_string()))
    }
}

fn real<T>(items: &[T], f: impl Fn(&T) -> f64) -> Column {
    Column::Real(items.iter().map(f).collect())
}

/// The fields of one instant: `x_m, p_Pa, q_Pa, g_C_per_m2, sigma_xx_Pa, d_x_C_per_m2`.
pub fn fields_table(points: &[SurfacePoint]) -> Table {
    Table {
        columns: vec![
            ("x_m", real(points, |p| p.x)),
            ("p_Pa", real(points, |p| p.pressure)),
            ("q_Pa", real(points, |p| p.traction)),
            ("g_C_per_m2", real(points, |p| p.charge)),
            ("sigma_xx_Pa", real(points, |p| p.sigma_xx)),
            ("d_x_C_per_m2", real(points, |p| p.d_x)),
        ],
    }
}

/// `cycles.csv`: one row per fretting cycle.
pub fn cycles_table(cycles: &[CycleRow]) -> Table {
    let c = cycles;
    Table {
        columns: vec![
            ("cycle", Column::Count(c.iter().map(|c| c.cycle).collect())),
            (
                "first_step",
                Column::Count(c.iter().map(|c| c.steps.0).collect()),
            ),
            (
                "last_step",
                Column::Count(c.iter().map(|c| c.steps.1).collect()),
            ),
            ("Q_start_N_per_m", real(c, |c| c.loads.0)),
            ("Q_min_N_per_m", real(c, |c| c.loads.1)),
            ("Q_end_N_per_m", real(c, |c| c.loads.2)),
            ("loop_area_J_per_m", real(c, |c| c.loop_area)),
            ("friction_work_J_per_m", real(c, |c| c.friction_work)),
            ("normal_work_J_per_m", real(c, |c| c.normal_work)),
            ("electric_work_J_per_m", real(c, |c| c.electric_work)),
            ("delta_at_max_m", real(c, |c| c.displacement_extremes.0)),
            ("delta_at_min_m", real(c, |c| c.displacement_extremes.1)),
            ("stick_lo_at_max_m", real(c, |c| c.stick_at_max.0)),
            ("stick_hi_at_max_m", real(c, |c| c.stick_at_max.1)),
            ("stick_lo_at_min_m", real(c, |c| c.stick_at_min.0)),
            ("stick_hi_at_min_m", real(c, |c| c.stick_at_min.1)),
            (
                "change_vs_previous",
                Column::MaybeReal(c.iter().map(|c| c.change).collect()),
            ),
            (
                "compared_with_cycle",
                Column::MaybeCount(c.iter().map(|c| c.compared_with).collect()),
            ),
            (
                "regime",
                Column::Text(c.iter().map(|c| word(&c.regime)).collect()),
            ),
            (
                "slip_amplitude_m",
                Column::MaybeReal(c.iter().map(|c| c.slip_amplitude).collect()),
            ),
            (
                "energy_ratio",
                Column::MaybeReal(c.iter().map(|c| c.energy_ratio).collect()),
            ),
            (
                "max_local_slip_m",
                Column::MaybeReal(c.iter().map(|c| c.max_local_slip).collect()),
            ),
        ],
    }
}

/// The word serde writes for a unit enum variant (`"forward_slip"`, `"gross_slip"`).
fn word<T: serde::Serialize>(value: &T) -> String {
    serde_json::to_value(value)
        .ok()
        .and_then(|v| v.as_str().map(String::from))
        .unwrap_or_default()
}

/// `steps.csv`: one row per accepted step; `friction` is η. The column `bulk_stress_Pa`
/// (after `potential_V`) is there when a record has a bulk stress.
pub fn steps_table(records: &[StepRecord], friction: f64) -> Table {
    let bulk = records.iter().any(|r| r.bulk_stress != 0.0);
    steps_table_of(records, friction, bulk)
}

/// [`steps_table`] with the column `bulk_stress_Pa` where `bulk` is true.
pub(crate) fn steps_table_of(records: &[StepRecord], friction: f64, bulk: bool) -> Table {
    let mut table = all_steps_columns(records, friction);
    if !bulk {
        table.columns.retain(|(name, _)| *name != "bulk_stress_Pa");
    }
    table
}

fn all_steps_columns(records: &[StepRecord], friction: f64) -> Table {
    let r = records;
    let regime = |r: &StepRecord| word(&r.regime);
    Table {
        columns: vec![
            ("step", Column::Count(r.iter().map(|r| r.step).collect())),
            ("t_s", real(r, |r| r.t)),
            ("Q_N_per_m", real(r, |r| r.q)),
            ("Q_over_etaP", real(r, |r| r.q / (friction * r.normal_load))),
            ("P_N_per_m", real(r, |r| r.normal_load)),
            ("charge_C_per_m", real(r, |r| r.charge)),
            ("potential_V", real(r, |r| r.potential)),
            ("bulk_stress_Pa", real(r, |r| r.bulk_stress)),
            ("regime", Column::Text(r.iter().map(regime).collect())),
            ("phase", Column::Count(r.iter().map(|r| r.phase).collect())),
            ("a_m", real(r, |r| r.half_width)),
            ("e_m", real(r, |r| r.eccentricity)),
            ("stick_lo_m", real(r, |r| r.stick_lo)),
            ("stick_hi_m", real(r, |r| r.stick_hi)),
            ("left_slip_sign", real(r, |r| r.left_slip_sign)),
            ("right_slip_sign", real(r, |r| r.right_slip_sign)),
            (
                "newton_iterations",
                Column::Count(r.iter().map(|r| r.iterations).collect()),
            ),
            (
                "evaluations",
                Column::Count(r.iter().map(|r| r.newton_iterations).collect()),
            ),
            ("residual", real(r, |r| r.residual)),
            ("stick_excess", real(r, |r| r.admissibility.stick_excess)),
            ("slip_reversal", real(r, |r| r.admissibility.slip_reversal)),
            ("delta_m", real(r, |r| r.displacement)),
            ("dissipation_J_per_m", real(r, |r| r.dissipation)),
            (
                "solver",
                Column::Text(r.iter().map(|r| r.solver.word().into()).collect()),
            ),
            (
                "stick_zones",
                Column::Count(r.iter().map(|r| r.zones.stick).collect()),
            ),
            (
                "slip_zones",
                Column::Count(r.iter().map(|r| r.zones.slip).collect()),
            ),
            (
                "slip_sign_changes",
                Column::Count(r.iter().map(|r| r.zones.sign_changes).collect()),
            ),
        ],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `steps.csv` written as the records arrive, in blocks, has the bytes of the whole table's
    /// CSV, over more records than a block (the default run's records repeated to 80 times
    /// their number).
    #[test]
    fn steps_written_in_blocks_are_the_whole_tables_bytes() {
        let scenario = crate::scenario::default_scenario();
        let solution = crate::io::solve(&scenario, &mut crate::history::NoObserver).unwrap();
        let n = solution.records.len();
        let records: Vec<StepRecord> = (0..80 * n)
            .map(|k| StepRecord {
                step: k,
                ..solution.records[k % n].clone()
            })
            .collect();
        assert!(records.len() > 2 * STEPS_BLOCK);
        let friction = scenario.model.friction;
        let mut csv = StepsCsv::new(Vec::new(), friction, false).unwrap();
        for r in &records {
            csv.push(r).unwrap();
        }
        assert!(csv.finish().unwrap() == steps_table(&records, friction).csv());
    }
}
