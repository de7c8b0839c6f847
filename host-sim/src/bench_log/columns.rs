//! The contract's columns and metadata (`bench-log.md`, "File" and "Columns"): the
//! [`Signal`] of each column name with its unit and whether it is required, the metadata
//! keys `eha` reads ([`DRIVE_KEY`], [`RECORDED_AT_KEY`]), the fewest rows a log holds
//! ([`MIN_ROWS`]), and [`BenchLog`], a log in memory: its metadata and one vector per
//! column.

/// The fewest data rows a bench log may have.
pub const MIN_ROWS: usize = 100;

/// Metadata key naming the actuator a log comes from (`# drive: ID`).
pub const DRIVE_KEY: &str = "drive";

/// Metadata key of the time a log started (`# recorded_at: 2026-11-30T14:05:00Z`, RFC 3339).
pub const RECORDED_AT_KEY: &str = "recorded_at";

/// A column of the contract.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Signal {
    /// `t_s`: time since the start of the log, strictly increasing. [s]
    Time,
    /// `p_ref_pa`: pressure setpoint seen by the controller. [Pa]
    PressureRef,
    /// `p_pa`: measured pressure on the pump's high-pressure port. [Pa]
    Pressure,
    /// `speed_rad_s`: measured shaft speed. [rad/s]
    Speed,
    /// `iq_a`: measured q-axis current. [A]
    Iq,
    /// `id_a`: measured d-axis current. [A]
    Id,
    /// `theta_m_rad`: shaft mechanical angle. [rad]
    ThetaM,
    /// `x_m`: piston position from mid-stroke. [m]
    PistonPosition,
    /// `p_low_pa`: pressure on the pump's low-pressure port. [Pa]
    PressureLow,
    /// `speed_ref_rad_s`: speed reference. [rad/s]
    SpeedRef,
    /// `iq_ref_a`: q-current reference. [A]
    IqRef,
    /// `ud_v`: commanded d-axis voltage. [V]
    Ud,
    /// `uq_v`: commanded q-axis voltage. [V]
    Uq,
    /// `udc_v`: measured DC-link voltage. [V]
    Udc,
    /// `oil_temp_c`: oil temperature. [°C]
    OilTemp,
}

impl Signal {
    /// Every column, required ones first, in the order the writer puts them.
    pub const ALL: [Signal; 15] = [
        Signal::Time,
        Signal::PressureRef,
        Signal::Pressure,
        Signal::Speed,
        Signal::Iq,
        Signal::Id,
        Signal::ThetaM,
        Signal::PistonPosition,
        Signal::PressureLow,
        Signal::SpeedRef,
        Signal::IqRef,
        Signal::Ud,
        Signal::Uq,
        Signal::Udc,
        Signal::OilTemp,
    ];

    /// The column name in the file.
    pub const fn name(self) -> &'static str {
        match self {
            Signal::Time => "t_s",
            Signal::PressureRef => "p_ref_pa",
            Signal::Pressure => "p_pa",
            Signal::Speed => "speed_rad_s",
            Signal::Iq => "iq_a",
            Signal::Id => "id_a",
            Signal::ThetaM => "theta_m_rad",
            Signal::PistonPosition => "x_m",
            Signal::PressureLow => "p_low_pa",
            Signal::SpeedRef => "speed_ref_rad_s",
            Signal::IqRef => "iq_ref_a",
            Signal::Ud => "ud_v",
            Signal::Uq => "uq_v",
            Signal::Udc => "udc_v",
            Signal::OilTemp => "oil_temp_c",
        }
    }

    /// Whether every bench log must have this column.
    pub const fn is_required(self) -> bool {
        matches!(
            self,
            Signal::Time
                | Signal::PressureRef
                | Signal::Pressure
                | Signal::Speed
                | Signal::Iq
                | Signal::Id
        )
    }

    /// The signal of a column name, if the contract knows it.
    pub fn from_name(name: &str) -> Option<Signal> {
        Signal::ALL.into_iter().find(|s| s.name() == name)
    }
}

/// One bench log: metadata and one vector per column, all of the same length.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BenchLog {
    /// The `# key: value` lines, in file order (unknown keys included).
    pub metadata: Vec<(String, String)>,
    /// Time since the start of the log, strictly increasing. [s]
    pub t_s: Vec<f64>,
    /// Pressure setpoint seen by the controller. [Pa]
    pub p_ref_pa: Vec<f64>,
    /// Measured pressure on the pump's high-pressure port (gauge). [Pa]
    pub p_pa: Vec<f64>,
    /// Measured motor (= pump) shaft speed. [rad/s]
    pub speed_rad_s: Vec<f64>,
    /// Measured q-axis current (amplitude-invariant Park transform). [A]
    pub iq_a: Vec<f64>,
    /// Measured d-axis current. [A]
    pub id_a: Vec<f64>,
    /// Shaft mechanical angle, wrapped or unwrapped. [rad]
    pub theta_m_rad: Option<Vec<f64>>,
    /// Piston position from mid-stroke; absent means blocked. [m]
    pub x_m: Option<Vec<f64>>,
    /// Pressure on the pump's low-pressure port (gauge). [Pa]
    pub p_low_pa: Option<Vec<f64>>,
    /// Speed reference. [rad/s]
    pub speed_ref_rad_s: Option<Vec<f64>>,
    /// q-current reference. [A]
    pub iq_ref_a: Option<Vec<f64>>,
    /// Commanded d-axis voltage. [V]
    pub ud_v: Option<Vec<f64>>,
    /// Commanded q-axis voltage. [V]
    pub uq_v: Option<Vec<f64>>,
    /// Measured DC-link voltage. [V]
    pub udc_v: Option<Vec<f64>>,
    /// Oil temperature. [°C]
    pub oil_temp_c: Option<Vec<f64>>,
}

/// Whether a row at time `t_s` is kept after the last kept row's time `last_kept_s` when
/// rows are kept at least `min_interval_s` apart (the first row always). [s]
pub(super) fn keeps_row(last_kept_s: Option<f64>, t_s: f64, min_interval_s: f64) -> bool {
    last_kept_s.is_none_or(|last| t_s - last >= min_interval_s)
}

/// Rows whose intervals tell whether a log is thinned at all. [1]
pub const THINNING_PROBE_ROWS: usize = 65;

/// Whether a log whose rows start at the times `t` [s] is sampled faster than
/// `min_interval_s` [s], so that it is thinned: the median of its first
/// [`THINNING_PROBE_ROWS`] rows' intervals lies below it. A log at or below that rate is
/// read whole, so that stamps scattered about a 2 kHz grid do not lose the rows that came
/// in early.
pub(super) fn faster_than(t: &[f64], min_interval_s: f64) -> bool {
    let head = &t[..t.len().min(THINNING_PROBE_ROWS)];
    let mut d: Vec<f64> = head.windows(2).map(|w| w[1] - w[0]).collect();
    d.sort_by(f64::total_cmp);
    d.get(d.len() / 2).is_some_and(|m| *m < min_interval_s)
}

impl BenchLog {
    /// Number of samples (rows).
    pub fn len(&self) -> usize {
        self.t_s.len()
    }

    /// True when there are no samples.
    pub fn is_empty(&self) -> bool {
        self.t_s.is_empty()
    }

    /// The log from row `from` on (clamped to the last row), its time restarted at zero.
    pub fn tail(&self, from: usize) -> BenchLog {
        let k = from.min(self.len().saturating_sub(1));
        let cut = |v: &Vec<f64>| v.get(k..).map_or_else(Vec::new, <[f64]>::to_vec);
        let cut_opt = |v: &Option<Vec<f64>>| v.as_ref().map(cut);
        let t0 = self.t_s.get(k).copied().unwrap_or(0.0);
        BenchLog {
            metadata: self.metadata.clone(),
            t_s: cut(&self.t_s).into_iter().map(|t| t - t0).collect(),
            p_ref_pa: cut(&self.p_ref_pa),
            p_pa: cut(&self.p_pa),
            speed_rad_s: cut(&self.speed_rad_s),
            iq_a: cut(&self.iq_a),
            id_a: cut(&self.id_a),
            theta_m_rad: cut_opt(&self.theta_m_rad),
            x_m: cut_opt(&self.x_m),
            p_low_pa: cut_opt(&self.p_low_pa),
            speed_ref_rad_s: cut_opt(&self.speed_ref_rad_s),
            iq_ref_a: cut_opt(&self.iq_ref_a),
            ud_v: cut_opt(&self.ud_v),
            uq_v: cut_opt(&self.uq_v),
            udc_v: cut_opt(&self.udc_v),
            oil_temp_c: cut_opt(&self.oil_temp_c),
        }
    }

    /// The rows at least `min_interval_s` after the last row kept (the first row always) of
    /// a log sampled faster than that ([`faster_than`]), as [`super::read_thinned`] keeps
    /// them; `None` when every row is kept.
    pub fn thinned(&self, min_interval_s: f64) -> Option<BenchLog> {
        if !faster_than(&self.t_s, min_interval_s) {
            return None;
        }
        let mut keep = Vec::with_capacity(self.len());
        let mut last = None;
        for (k, &t) in self.t_s.iter().enumerate() {
            if keeps_row(last, t, min_interval_s) {
                keep.push(k);
                last = Some(t);
            }
        }
        if keep.len() == self.len() {
            return None;
        }
        Some(self.each_column(|column| keep.iter().map(|&k| column[k]).collect()))
    }

    /// The rows `rows` (clamped to the log), their times as logged, the metadata kept.
    pub fn rows(&self, rows: std::ops::Range<usize>) -> BenchLog {
        let end = rows.end.min(self.len());
        let rows = rows.start.min(end)..end;
        self.each_column(|column| column[rows.clone()].to_vec())
    }

    /// A log with this one's metadata and each column `pick` makes of this one's; a column
    /// let go (empty, see [`BenchLog::check_holding`]) stays empty.
    fn each_column(&self, pick: impl Fn(&[f64]) -> Vec<f64>) -> BenchLog {
        let mut out = BenchLog {
            metadata: self.metadata.clone(),
            ..BenchLog::default()
        };
        for (signal, column) in self.columns().filter(|(_, c)| !c.is_empty()) {
            *out.column_mut(signal) = pick(column);
        }
        out
    }

    /// The value of the first metadata line with `key`.
    pub fn meta(&self, key: &str) -> Option<&str> {
        self.metadata
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    /// The actuator the log comes from (`# drive: ID`), if the log names it.
    pub fn drive(&self) -> Option<&str> {
        self.meta(DRIVE_KEY)
    }

    /// When the log started (`# recorded_at: …`, RFC 3339, as written), if the log says.
    pub fn recorded_at(&self) -> Option<&str> {
        self.meta(RECORDED_AT_KEY)
    }

    /// The column of `signal`, `None` for an absent optional column.
    pub fn column(&self, signal: Signal) -> Option<&[f64]> {
        let c = match signal {
            Signal::Time => &self.t_s,
            Signal::PressureRef => &self.p_ref_pa,
            Signal::Pressure => &self.p_pa,
            Signal::Speed => &self.speed_rad_s,
            Signal::Iq => &self.iq_a,
            Signal::Id => &self.id_a,
            Signal::ThetaM => return self.theta_m_rad.as_deref(),
            Signal::PistonPosition => return self.x_m.as_deref(),
            Signal::PressureLow => return self.p_low_pa.as_deref(),
            Signal::SpeedRef => return self.speed_ref_rad_s.as_deref(),
            Signal::IqRef => return self.iq_ref_a.as_deref(),
            Signal::Ud => return self.ud_v.as_deref(),
            Signal::Uq => return self.uq_v.as_deref(),
            Signal::Udc => return self.udc_v.as_deref(),
            Signal::OilTemp => return self.oil_temp_c.as_deref(),
        };
        Some(c)
    }

    /// The column of `signal` for filling, created empty if it was an absent optional one.
    pub fn column_mut(&mut self, signal: Signal) -> &mut Vec<f64> {
        match self.field(signal) {
            Field::Required(c) => c,
            Field::Optional(c) => c.get_or_insert_with(Vec::new),
        }
    }

    /// Takes the optional column of `signal` out of the log (as a bench that did not log
    /// it would have written it); `false`, and nothing changed, for a required one.
    pub fn remove(&mut self, signal: Signal) -> bool {
        match self.field(signal) {
            Field::Required(_) => false,
            Field::Optional(c) => {
                *c = None;
                true
            }
        }
    }

    /// The field that holds `signal`.
    fn field(&mut self, signal: Signal) -> Field<'_> {
        match signal {
            Signal::Time => Field::Required(&mut self.t_s),
            Signal::PressureRef => Field::Required(&mut self.p_ref_pa),
            Signal::Pressure => Field::Required(&mut self.p_pa),
            Signal::Speed => Field::Required(&mut self.speed_rad_s),
            Signal::Iq => Field::Required(&mut self.iq_a),
            Signal::Id => Field::Required(&mut self.id_a),
            Signal::ThetaM => Field::Optional(&mut self.theta_m_rad),
            Signal::PistonPosition => Field::Optional(&mut self.x_m),
            Signal::PressureLow => Field::Optional(&mut self.p_low_pa),
            Signal::SpeedRef => Field::Optional(&mut self.speed_ref_rad_s),
            Signal::IqRef => Field::Optional(&mut self.iq_ref_a),
            Signal::Ud => Field::Optional(&mut self.ud_v),
            Signal::Uq => Field::Optional(&mut self.uq_v),
            Signal::Udc => Field::Optional(&mut self.udc_v),
            Signal::OilTemp => Field::Optional(&mut self.oil_temp_c),
        }
    }

    /// The columns present, in writing order.
    pub fn columns(&self) -> impl Iterator<Item = (Signal, &[f64])> {
        Signal::ALL
            .into_iter()
            .filter_map(|s| self.column(s).map(|c| (s, c)))
    }
}

/// A column's field in a [`BenchLog`]: a required one, or an optional one that may be absent.
enum Field<'a> {
    Required(&'a mut Vec<f64>),
    Optional(&'a mut Option<Vec<f64>>),
}
