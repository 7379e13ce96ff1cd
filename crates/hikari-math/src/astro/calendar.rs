//! Date-time arithmetic on [`DateTime`]: adding seconds across day, month and year
//! boundaries (what a time-lapse that runs past midnight needs), in the proleptic Gregorian
//! calendar of local civil time. The UTC offset is kept: no time-zone or daylight-saving
//! changes happen along the way.

use super::time::{AstroError, DateTime};

/// Days from 1970-01-01 to the Gregorian date `(y, m, d)` (negative before it); Howard
/// Hinnant's `days_from_civil`.
pub fn days_from_civil(y: i32, m: u32, d: u32) -> i64 {
    let y = i64::from(y) - i64::from(m <= 2);
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let m = i64::from(m);
    let doy = (153 * (if m > 2 { m - 3 } else { m + 9 }) + 2) / 5 + i64::from(d) - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

/// The Gregorian date `(y, m, d)` of a day counted from 1970-01-01; the inverse of
/// [`days_from_civil`] (Hinnant's `civil_from_days`).
pub fn civil_from_days(z: i64) -> (i32, u32, u32) {
    let z = z + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    let y = yoe + era * 400 + i64::from(m <= 2);
    (y as i32, m, d)
}

impl DateTime {
    /// Seconds since local midnight.
    pub fn seconds_of_day(&self) -> u32 {
        let (h, m, s) = self.time();
        h * 3600 + m * 60 + s
    }

    /// This local date and time moved by `seconds` (negative: earlier), across days, months
    /// and years, at the same UTC offset. An error if the result leaves
    /// [`super::time::YEARS`].
    pub fn plus_seconds(&self, seconds: i64) -> Result<DateTime, AstroError> {
        let (y, m, d) = self.date();
        let total = days_from_civil(y, m, d) * 86_400 + i64::from(self.seconds_of_day()) + seconds;
        let (day, sod) = (total.div_euclid(86_400), total.rem_euclid(86_400));
        let (y, m, d) = civil_from_days(day);
        let sod = sod as u32;
        DateTime::new(
            y,
            m,
            d,
            sod / 3600,
            sod / 60 % 60,
            sod % 60,
            self.utc_offset_h(),
        )
    }

    /// `YYYY-MM-DD`, as [`DateTime::parse`] reads it.
    pub fn date_string(&self) -> String {
        let (y, m, d) = self.date();
        format!("{y:04}-{m:02}-{d:02}")
    }

    /// `HH:MM:SS`, as [`DateTime::parse`] reads it.
    pub fn time_string(&self) -> String {
        let (h, m, s) = self.time();
        format!("{h:02}:{m:02}:{s:02}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Julian day number of a Gregorian date by Fliegel and Van Flandern (1968), integer
    /// arithmetic truncating toward zero as in their Fortran: an independent reference.
    fn fliegel_van_flandern(y: i64, m: i64, d: i64) -> i64 {
        d - 32075 + 1461 * (y + 4800 + (m - 14) / 12) / 4 + 367 * (m - 2 - (m - 14) / 12 * 12) / 12
            - 3 * ((y + 4900 + (m - 14) / 12) / 100) / 4
    }

    fn at(date: &str, time: &str) -> DateTime {
        DateTime::parse(date, time, 9.0).unwrap()
    }

    fn shown(t: &DateTime) -> String {
        format!("{} {}", t.date_string(), t.time_string())
    }

    #[test]
    fn known_calendar_facts() {
        let cases = [
            ("2024-02-28", "23:30", 3600, "2024-02-29 00:30:00"),
            ("2023-02-28", "23:30", 3600, "2023-03-01 00:30:00"),
            ("2023-12-31", "23:00", 7200, "2024-01-01 01:00:00"),
            ("2100-02-28", "12:00", 86_400, "2100-03-01 12:00:00"),
            ("2000-02-28", "12:00", 86_400, "2000-02-29 12:00:00"),
            ("2024-07-21", "18:00", 12 * 3600, "2024-07-22 06:00:00"),
            ("2024-03-01", "00:00:05", -10, "2024-02-29 23:59:55"),
            ("2024-01-01", "00:00", -1, "2023-12-31 23:59:59"),
            ("2024-07-21", "12:34:56", 0, "2024-07-21 12:34:56"),
        ];
        for (date, time, dt, want) in cases {
            let got = at(date, time).plus_seconds(dt).unwrap();
            assert_eq!(shown(&got), want, "{date} {time} + {dt} s");
            assert_eq!(got.utc_offset_h(), 9.0);
        }
        assert!(at("2100-12-31", "23:00").plus_seconds(3600).is_err());
    }

    #[test]
    fn day_counts_agree_with_fliegel_van_flandern_over_the_whole_range() {
        // JDN 2440588 is 1970-01-01.
        let mut t = at("1900-01-01", "00:00");
        let mut day = 0;
        loop {
            let (y, m, d) = t.date();
            let jdn = fliegel_van_flandern(i64::from(y), i64::from(m), i64::from(d));
            assert_eq!(days_from_civil(y, m, d), jdn - 2_440_588, "{y}-{m}-{d}");
            assert_eq!(civil_from_days(jdn - 2_440_588), (y, m, d));
            // And the Julian day of the instant (Meeus) advances by exactly one a day.
            let jd0 = at("1900-01-01", "00:00").julian_day_ut();
            assert!((t.julian_day_ut() - jd0 - f64::from(day)).abs() < 1e-6);
            match t.plus_seconds(86_400) {
                Ok(next) => t = next,
                Err(_) => break,
            }
            day += 1;
        }
        assert_eq!(shown(&t), "2100-12-31 00:00:00");
        // 201 years, 49 of them leap (2000 is, 1900 and 2100 are not).
        assert_eq!(day + 1, 201 * 365 + 49);
    }

    #[test]
    fn odd_steps_land_where_whole_days_and_seconds_say() {
        let start = at("2023-12-31", "22:17:03");
        for dt in [1i64, 59, 3599, 86_399, 86_401, 1_000_003, -7_777_777] {
            let t = start.plus_seconds(dt).unwrap();
            let days = |t: &DateTime| {
                let (y, m, d) = t.date();
                days_from_civil(y, m, d) * 86_400 + i64::from(t.seconds_of_day())
            };
            assert_eq!(days(&t) - days(&start), dt);
            assert_eq!(t.plus_seconds(-dt).unwrap(), start);
        }
    }
}
