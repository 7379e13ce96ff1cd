//! Inputs (a local date and time with its UTC offset, a place) with their validation, the
//! Julian day and ΔT.

/// Bad date, time or place; each names the field and its allowed range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AstroError {
    /// A date that cannot be read or lies outside 1900-01-01..=2100-12-31.
    #[error("date `{text}`: {why}; expected YYYY-MM-DD from 1900-01-01 to 2100-12-31")]
    Date {
        /// The text given (or the numbers, formatted).
        text: String,
        /// What is wrong with it.
        why: String,
    },
    /// A time of day that cannot be read or is 24:00 or later.
    #[error("time `{text}`: {why}; expected HH:MM or HH:MM:SS from 00:00 to 23:59:59")]
    Time {
        /// The text given (or the numbers, formatted).
        text: String,
        /// What is wrong with it.
        why: String,
    },
    /// A number outside its range (or NaN).
    #[error("{field} = {value} is outside the allowed range {allowed}")]
    OutOfRange {
        /// `latitude`, `longitude` or `utc_offset`.
        field: &'static str,
        /// The value given.
        value: f64,
        /// The allowed range, with its unit.
        allowed: &'static str,
    },
}

/// Earliest and latest years accepted (the range of the ΔT polynomials used and of the
/// truncated theories' stated accuracy).
pub const YEARS: std::ops::RangeInclusive<i32> = 1900..=2100;

/// A local civil date and time with its offset from UTC.
///
/// The time is read as UT (UT1 = UTC; the difference, under 0.9 s, moves the sky by at most
/// 0.004°). Before 1972 "UTC" here simply means UT.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DateTime {
    year: i32,
    month: u32,
    day: u32,
    hour: u32,
    minute: u32,
    second: u32,
    utc_offset_h: f64,
}

fn is_leap(year: i32) -> bool {
    (year % 4 == 0 && year % 100 != 0) || year % 400 == 0
}

fn days_in_month(year: i32, month: u32) -> u32 {
    match month {
        2 if is_leap(year) => 29,
        2 => 28,
        4 | 6 | 9 | 11 => 30,
        _ => 31,
    }
}

fn digits(t: &str, n: usize) -> bool {
    t.len() == n && t.bytes().all(|b| b.is_ascii_digit())
}

impl DateTime {
    /// The default date and time: 2024-07-21 12:00 at UTC+9 (Tsushima's time zone), a summer
    /// day whose night has a full moon (full at 10:17 UTC that day), so the renderer's night
    /// keys have moonlight.
    pub fn default_summer() -> Self {
        DateTime {
            year: 2024,
            month: 7,
            day: 21,
            hour: 12,
            minute: 0,
            second: 0,
            utc_offset_h: 9.0,
        }
    }

    /// A validated date and time: year within [`YEARS`], a real calendar day (Gregorian),
    /// `hour` 0..=23, `minute` and `second` 0..=59, `utc_offset_h` (hours east of Greenwich)
    /// within ±14.
    pub fn new(
        year: i32,
        month: u32,
        day: u32,
        hour: u32,
        minute: u32,
        second: u32,
        utc_offset_h: f64,
    ) -> Result<Self, AstroError> {
        let date_err = |why: &str| AstroError::Date {
            text: format!("{year:04}-{month:02}-{day:02}"),
            why: why.into(),
        };
        if !YEARS.contains(&year) {
            return Err(date_err("the year is outside 1900..=2100"));
        }
        if !(1..=12).contains(&month) {
            return Err(date_err("the month is not 01..=12"));
        }
        if day < 1 || day > days_in_month(year, month) {
            return Err(date_err("no such day in that month"));
        }
        let time_err = |why: &str| AstroError::Time {
            text: format!("{hour:02}:{minute:02}:{second:02}"),
            why: why.into(),
        };
        if hour > 23 {
            return Err(time_err("the hour is past 23"));
        }
        if minute > 59 {
            return Err(time_err("the minutes are past 59"));
        }
        if second > 59 {
            return Err(time_err("the seconds are past 59"));
        }
        if !(utc_offset_h.is_finite() && utc_offset_h.abs() <= 14.0) {
            return Err(AstroError::OutOfRange {
                field: "utc_offset",
                value: utc_offset_h,
                allowed: "-14..=14 hours",
            });
        }
        Ok(DateTime {
            year,
            month,
            day,
            hour,
            minute,
            second,
            utc_offset_h,
        })
    }

    /// Parses `date` as YYYY-MM-DD and `time` as HH:MM or HH:MM:SS (one or two hour digits),
    /// then validates as [`DateTime::new`].
    pub fn parse(date: &str, time: &str, utc_offset_h: f64) -> Result<Self, AstroError> {
        let date_err = |why: &str| AstroError::Date {
            text: date.into(),
            why: why.into(),
        };
        let parts: Vec<&str> = date.split('-').collect();
        let [y, m, d] = parts[..] else {
            return Err(date_err("not three fields separated by `-`"));
        };
        if !(digits(y, 4) && digits(m, 2) && digits(d, 2)) {
            return Err(date_err("the fields must be 4, 2 and 2 digits"));
        }
        // Digit-only fields of bounded length cannot fail to parse.
        let (y, m, d): (i32, u32, u32) = (
            y.parse().unwrap_or(0),
            m.parse().unwrap_or(0),
            d.parse().unwrap_or(0),
        );
        let time_err = |why: &str| AstroError::Time {
            text: time.into(),
            why: why.into(),
        };
        let parts: Vec<&str> = time.split(':').collect();
        let (h, mi, s) = match parts[..] {
            [h, mi] => (h, mi, "00"),
            [h, mi, s] => (h, mi, s),
            _ => return Err(time_err("not two or three fields separated by `:`")),
        };
        if !((digits(h, 1) || digits(h, 2)) && digits(mi, 2) && digits(s, 2)) {
            return Err(time_err(
                "the hour must be one or two digits, minutes and seconds two",
            ));
        }
        let (h, mi, s): (u32, u32, u32) = (
            h.parse().unwrap_or(99),
            mi.parse().unwrap_or(99),
            s.parse().unwrap_or(99),
        );
        match DateTime::new(y, m, d, h, mi, s, utc_offset_h) {
            Err(AstroError::Date { why, .. }) => Err(date_err(&why)),
            Err(AstroError::Time { why, .. }) => Err(time_err(&why)),
            other => other,
        }
    }

    /// Local calendar date `(year, month, day)`.
    pub fn date(&self) -> (i32, u32, u32) {
        (self.year, self.month, self.day)
    }

    /// Local time `(hour, minute, second)`.
    pub fn time(&self) -> (u32, u32, u32) {
        (self.hour, self.minute, self.second)
    }

    /// Offset of the local time from UTC, hours (positive east: Japan is +9).
    pub fn utc_offset_h(&self) -> f64 {
        self.utc_offset_h
    }

    /// Julian day of this instant on the UT scale (Meeus, *Astronomical Algorithms*, eq. 7.1,
    /// Gregorian calendar).
    pub fn julian_day_ut(&self) -> f64 {
        let (mut y, mut m) = (self.year as f64, self.month as f64);
        if self.month <= 2 {
            y -= 1.0;
            m += 12.0;
        }
        let a = (y / 100.0).floor();
        let b = 2.0 - a + (a / 4.0).floor();
        let day_fraction =
            (self.hour as f64 * 3600.0 + self.minute as f64 * 60.0 + self.second as f64) / 86400.0
                - self.utc_offset_h / 24.0;
        (365.25 * (y + 4716.0)).floor() + (30.6001 * (m + 1.0)).floor() + self.day as f64 + b
            - 1524.5
            + day_fraction
    }
}

/// A place on the WGS84 ellipsoid, at sea level.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Place {
    latitude_deg: f64,
    longitude_deg: f64,
}

impl Place {
    /// Tsushima, Japan: 34.4° N, 129.3° E (use with a UTC offset of +9 h).
    pub const TSUSHIMA: Place = Place {
        latitude_deg: 34.4,
        longitude_deg: 129.3,
    };

    /// A validated place: geodetic latitude within ±90° (north positive), longitude within
    /// ±180° (east positive).
    pub fn new(latitude_deg: f64, longitude_deg: f64) -> Result<Self, AstroError> {
        if !(latitude_deg.is_finite() && latitude_deg.abs() <= 90.0) {
            return Err(AstroError::OutOfRange {
                field: "latitude",
                value: latitude_deg,
                allowed: "-90..=90 degrees",
            });
        }
        if !(longitude_deg.is_finite() && longitude_deg.abs() <= 180.0) {
            return Err(AstroError::OutOfRange {
                field: "longitude",
                value: longitude_deg,
                allowed: "-180..=180 degrees",
            });
        }
        Ok(Place {
            latitude_deg,
            longitude_deg,
        })
    }

    /// Geodetic latitude, degrees (north positive).
    pub fn latitude_deg(&self) -> f64 {
        self.latitude_deg
    }

    /// Longitude, degrees (east positive).
    pub fn longitude_deg(&self) -> f64 {
        self.longitude_deg
    }
}

impl Default for Place {
    fn default() -> Self {
        Place::TSUSHIMA
    }
}

/// ΔT = TT − UT in seconds, from Espenak & Meeus's polynomials ("Five Millennium Canon of
/// Solar Eclipses", NASA/TP-2006-214141, and NASA's eclipse web site), for a decimal year.
/// Valid 1860..2150 (the year is clamped to that span); the pieces used here cover
/// 1860..=2150, so the inputs' 1900..=2100 (and the UTC instants up to 14 h beyond) are inside.
pub fn delta_t_seconds(year: f64) -> f64 {
    let y = year.clamp(1860.0, 2150.0);
    if y < 1900.0 {
        let t = y - 1860.0;
        7.62 + 0.5737 * t - 0.251754 * t.powi(2) + 0.01680668 * t.powi(3) - 0.0004473624 * t.powi(4)
            + t.powi(5) / 233174.0
    } else if y < 1920.0 {
        let t = y - 1900.0;
        -2.79 + 1.494119 * t - 0.0598939 * t.powi(2) + 0.0061966 * t.powi(3) - 0.000197 * t.powi(4)
    } else if y < 1941.0 {
        let t = y - 1920.0;
        21.20 + 0.84493 * t - 0.076100 * t.powi(2) + 0.0020936 * t.powi(3)
    } else if y < 1961.0 {
        let t = y - 1950.0;
        29.07 + 0.407 * t - t.powi(2) / 233.0 + t.powi(3) / 2547.0
    } else if y < 1986.0 {
        let t = y - 1975.0;
        45.45 + 1.067 * t - t.powi(2) / 260.0 - t.powi(3) / 718.0
    } else if y < 2005.0 {
        let t = y - 2000.0;
        63.86 + 0.3345 * t - 0.060374 * t.powi(2)
            + 0.0017275 * t.powi(3)
            + 0.000651814 * t.powi(4)
            + 0.00002373599 * t.powi(5)
    } else if y < 2050.0 {
        let t = y - 2000.0;
        62.92 + 0.32217 * t + 0.005589 * t.powi(2)
    } else {
        -20.0 + 32.0 * ((y - 1820.0) / 100.0).powi(2) - 0.5628 * (2150.0 - y)
    }
}

/// Decimal year of a Julian day (Julian years from J2000; what the ΔT polynomials take).
pub fn decimal_year(julian_day: f64) -> f64 {
    2000.0 + (julian_day - 2451545.0) / 365.25
}
