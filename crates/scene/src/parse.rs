//! Walking the spanned TOML tree: typed getters that report the exact key.

use std::ops::Range;

use glam::Vec3;
use toml::Spanned;
use toml::de::{DeTable, DeValue};

use crate::SceneFileError;

/// The source text and its name, for errors; and the command line's
/// overrides, whose values' spans lie past the text (see
/// [`crate::overrides`]).
pub(crate) struct Source<'s> {
    pub file: &'s str,
    pub text: &'s str,
    pub overrides: &'s [&'s str],
    /// Where each override's spans start.
    pub bases: Vec<usize>,
}

impl Source<'_> {
    pub fn error(
        &self,
        span: Range<usize>,
        key: &str,
        message: impl Into<String>,
    ) -> SceneFileError {
        match self.which_override(span.start) {
            Some(i) => {
                let base = self.bases[i];
                SceneFileError::new(
                    crate::overrides::LABEL,
                    self.overrides[i],
                    span.start - base..span.end.saturating_sub(base),
                    key,
                    message.into(),
                )
            }
            None => SceneFileError::new(self.file, self.text, span, key, message.into()),
        }
    }

    /// The override whose text `at` lies in, if it lies past the file's.
    fn which_override(&self, at: usize) -> Option<usize> {
        if at <= self.text.len() {
            return None;
        }
        self.bases.iter().rposition(|&b| b <= at)
    }

    /// Where the spans of override `i` start.
    pub fn override_base(&self, i: usize) -> usize {
        self.bases[i]
    }

    /// The text a span covers, in the file or an override.
    pub fn snippet(&self, span: Range<usize>) -> &str {
        let (text, span) = match self.which_override(span.start) {
            Some(i) => {
                let b = self.bases[i];
                (
                    self.overrides[i],
                    span.start - b..span.end.saturating_sub(b),
                )
            }
            None => (self.text, span),
        };
        text.get(span).unwrap_or("")
    }
}

/// " (did you mean `x`?)" when one of `choices` is a likely spelling of
/// `name` (at most a third of its letters off, two at least), else "".
pub(crate) fn did_you_mean<'c>(name: &str, choices: impl IntoIterator<Item = &'c str>) -> String {
    let limit = (name.chars().count() / 3).max(2);
    choices
        .into_iter()
        .map(|c| (strsim::damerau_levenshtein(name, c), c))
        .filter(|&(d, _)| d <= limit)
        .min_by_key(|&(d, _)| d)
        .map_or_else(String::new, |(_, c)| format!(" (did you mean `{c}`?)"))
}

/// A table being read, with the dotted path that leads to it.
pub(crate) struct Table<'a, 'i> {
    pub table: &'a DeTable<'i>,
    pub span: Range<usize>,
    pub path: String,
}

pub(crate) type Result<T> = std::result::Result<T, SceneFileError>;

impl<'a, 'i> Table<'a, 'i> {
    pub fn new(table: &'a DeTable<'i>, span: Range<usize>, path: String) -> Self {
        Table { table, span, path }
    }

    pub fn key_path(&self, key: &str) -> String {
        if self.path.is_empty() {
            key.to_owned()
        } else {
            format!("{}.{key}", self.path)
        }
    }

    pub fn get(&self, key: &str) -> Option<&'a Spanned<DeValue<'i>>> {
        self.table.get(key)
    }

    /// Rejects keys outside `allowed`, naming the first one in the file.
    pub fn deny_unknown(&self, src: &Source<'_>, allowed: &[&str]) -> Result<()> {
        let mut unknown: Vec<_> = self
            .table
            .iter()
            .filter(|(k, _)| !allowed.contains(&k.get_ref().as_ref()))
            .collect();
        unknown.sort_by_key(|(k, _)| k.span().start);
        if let Some((k, _)) = unknown.first() {
            let name: &str = k.get_ref();
            let expected = allowed
                .iter()
                .map(|a| format!("`{a}`"))
                .collect::<Vec<_>>()
                .join(", ");
            return Err(src.error(
                k.span(),
                &self.key_path(name),
                format!(
                    "unknown key `{name}`{}; expected one of {expected}",
                    did_you_mean(name, allowed.iter().copied())
                ),
            ));
        }
        Ok(())
    }

    pub fn missing(&self, src: &Source<'_>, key: &str, what: &str) -> SceneFileError {
        src.error(
            self.span.clone(),
            &self.key_path(key),
            format!("missing key `{key}` ({what})"),
        )
    }

    pub fn table(&self, src: &Source<'_>, key: &str) -> Result<Option<Table<'a, 'i>>> {
        match self.get(key) {
            None => Ok(None),
            Some(v) => Ok(Some(as_table(src, v, self.key_path(key))?)),
        }
    }

    pub fn str(&self, src: &Source<'_>, key: &str) -> Result<Option<(&'a str, Range<usize>)>> {
        match self.get(key) {
            None => Ok(None),
            Some(v) => match v.get_ref() {
                DeValue::String(s) => Ok(Some((s.as_ref(), v.span()))),
                other => Err(type_error(src, v, &self.key_path(key), "a string", other)),
            },
        }
    }

    pub fn req_str(
        &self,
        src: &Source<'_>,
        key: &str,
        what: &str,
    ) -> Result<(&'a str, Range<usize>)> {
        self.str(src, key)?
            .ok_or_else(|| self.missing(src, key, what))
    }

    pub fn f32(&self, src: &Source<'_>, key: &str) -> Result<Option<(f32, Range<usize>)>> {
        match self.get(key) {
            None => Ok(None),
            Some(v) => Ok(Some((number(src, v, &self.key_path(key))?, v.span()))),
        }
    }

    /// A required finite number satisfying `check` (which names the rule).
    pub fn req_f32(&self, src: &Source<'_>, key: &str, check: Check) -> Result<f32> {
        let (x, span) = self
            .f32(src, key)?
            .ok_or_else(|| self.missing(src, key, check.describe()))?;
        check.apply(src, x, span, &self.key_path(key))
    }

    pub fn opt_f32(&self, src: &Source<'_>, key: &str, check: Check, default: f32) -> Result<f32> {
        match self.f32(src, key)? {
            None => Ok(default),
            Some((x, span)) => check.apply(src, x, span, &self.key_path(key)),
        }
    }

    pub fn u64(&self, src: &Source<'_>, key: &str) -> Result<Option<(u64, Range<usize>)>> {
        match self.get(key) {
            None => Ok(None),
            Some(v) => match v.get_ref() {
                DeValue::Integer(i) => {
                    let digits = i.as_str().replace('_', "");
                    match u64::from_str_radix(&digits, i.radix()) {
                        Ok(n) => Ok(Some((n, v.span()))),
                        Err(_) => Err(src.error(
                            v.span(),
                            &self.key_path(key),
                            "must be a non-negative integer that fits in 64 bits",
                        )),
                    }
                }
                other => Err(type_error(
                    src,
                    v,
                    &self.key_path(key),
                    "a non-negative integer",
                    other,
                )),
            },
        }
    }

    /// An optional integer in `min..=max`.
    pub fn u32_in(&self, src: &Source<'_>, key: &str, min: u32, max: u32) -> Result<Option<u32>> {
        match self.u64(src, key)? {
            None => Ok(None),
            Some((n, _)) if n >= min as u64 && n <= max as u64 => Ok(Some(n as u32)),
            Some((n, span)) => Err(src.error(
                span,
                &self.key_path(key),
                format!("must be between {min} and {max}, got {n}"),
            )),
        }
    }

    pub fn vec3(&self, src: &Source<'_>, key: &str) -> Result<Option<(Vec3, Range<usize>)>> {
        let Some(v) = self.get(key) else {
            return Ok(None);
        };
        let path = self.key_path(key);
        let DeValue::Array(items) = v.get_ref() else {
            return Err(type_error(
                src,
                v,
                &path,
                "an array of 3 numbers",
                v.get_ref(),
            ));
        };
        if items.len() != 3 {
            return Err(src.error(
                v.span(),
                &path,
                format!("expected 3 numbers, found {}", items.len()),
            ));
        }
        let mut out = [0.0f32; 3];
        for (i, item) in items.iter().enumerate() {
            out[i] = number(src, item, &format!("{path}[{i}]"))?;
        }
        Ok(Some((Vec3::from(out), v.span())))
    }

    pub fn req_vec3(&self, src: &Source<'_>, key: &str, check: Check) -> Result<Vec3> {
        let (v, span) = self
            .vec3(src, key)?
            .ok_or_else(|| self.missing(src, key, check.describe()))?;
        check.apply_vec3(src, v, span, &self.key_path(key))
    }

    pub fn opt_vec3(
        &self,
        src: &Source<'_>,
        key: &str,
        check: Check,
        default: Vec3,
    ) -> Result<Vec3> {
        match self.vec3(src, key)? {
            None => Ok(default),
            Some((v, span)) => check.apply_vec3(src, v, span, &self.key_path(key)),
        }
    }
}

pub(crate) fn as_table<'a, 'i>(
    src: &Source<'_>,
    v: &'a Spanned<DeValue<'i>>,
    path: String,
) -> Result<Table<'a, 'i>> {
    match v.get_ref() {
        DeValue::Table(t) => Ok(Table::new(t, v.span(), path)),
        other => Err(type_error(src, v, &path, "a table", other)),
    }
}

fn type_error(
    src: &Source<'_>,
    v: &Spanned<DeValue<'_>>,
    path: &str,
    expected: &str,
    found: &DeValue<'_>,
) -> SceneFileError {
    src.error(
        v.span(),
        path,
        format!("expected {expected}, found {}", found.type_str()),
    )
}

/// A finite number, integer or float, as f32.
fn number(src: &Source<'_>, v: &Spanned<DeValue<'_>>, path: &str) -> Result<f32> {
    let x = match v.get_ref() {
        DeValue::Float(f) => {
            let text = f.as_str().replace('_', "");
            text.parse::<f64>().unwrap_or(f64::NAN)
        }
        DeValue::Integer(i) => {
            let digits = i.as_str().replace('_', "");
            i64::from_str_radix(&digits, i.radix())
                .map(|n| n as f64)
                .unwrap_or(f64::NAN)
        }
        other => return Err(type_error(src, v, path, "a number", other)),
    };
    let y = x as f32;
    if !y.is_finite() {
        return Err(src.error(
            v.span(),
            path,
            format!(
                "must be a finite number (within f32 range), got {}",
                src.snippet(v.span())
            ),
        ));
    }
    Ok(y)
}

/// A rule a number must satisfy.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Check {
    Any,
    Positive,
    NonNegative,
    UnitInterval,
    NonZeroVector,
    /// Radiance or irradiance: non-negative and at most [`MAX_EMISSION`].
    Emission,
}

/// Largest radiance or irradiance a file may give. Above it, one sample's
/// estimate (radiance times a path's throughput over its pdf), or the sum
/// of squares a pixel accumulates, can overflow f32 and the sample would be
/// dropped; 1e12 is far above any physical scene in any usual unit.
pub(crate) const MAX_EMISSION: f32 = 1e12;

/// Vectors that are normalised must have a length in this range: below,
/// the squared length is subnormal and the normalised vector is not of unit
/// length; above, the squared length overflows.
const MIN_VECTOR_LENGTH: f32 = 1.1e-19;
const MAX_VECTOR_LENGTH: f32 = 1.8e19;

impl Check {
    fn describe(self) -> &'static str {
        match self {
            Check::Any => "a number",
            Check::Positive => "a positive number",
            Check::NonNegative => "a non-negative number",
            Check::UnitInterval => "numbers between 0 and 1",
            Check::NonZeroVector => "a non-zero vector, of length between 1.1e-19 and 1.8e19",
            Check::Emission => "a non-negative number at most 1e12",
        }
    }

    fn ok(self, x: f32) -> bool {
        match self {
            Check::Any | Check::NonZeroVector => true,
            Check::Positive => x > 0.0,
            Check::NonNegative => x >= 0.0,
            Check::UnitInterval => (0.0..=1.0).contains(&x),
            Check::Emission => (0.0..=MAX_EMISSION).contains(&x),
        }
    }

    fn apply(self, src: &Source<'_>, x: f32, span: Range<usize>, path: &str) -> Result<f32> {
        if self.ok(x) {
            Ok(x)
        } else {
            Err(src.error(span, path, format!("must be {}, got {x}", self.describe())))
        }
    }

    fn apply_vec3(self, src: &Source<'_>, v: Vec3, span: Range<usize>, path: &str) -> Result<Vec3> {
        let ok = match self {
            Check::NonZeroVector => {
                (MIN_VECTOR_LENGTH..=MAX_VECTOR_LENGTH).contains(&v.length())
                    && v.length_squared() >= f32::MIN_POSITIVE
            }
            _ => v.to_array().iter().all(|&x| self.ok(x)),
        };
        if ok {
            Ok(v)
        } else {
            Err(src.error(
                span,
                path,
                format!(
                    "must be {}, got [{}, {}, {}]",
                    self.describe(),
                    v.x,
                    v.y,
                    v.z
                ),
            ))
        }
    }
}
