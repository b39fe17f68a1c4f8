//! `--set KEY=VALUE`: a scene key overridden from the command line (as
//! Mitsuba's `-D`), by its dotted path (`camera.vfov=30`,
//! `lights[0].radiance=[1,1,1]`). The value is parsed as TOML and put into
//! the file's spanned tree *before* validation, so it meets exactly the
//! checks the file's own value would; its spans lie past the file's text,
//! where [`Source`] finds the override to show in an error.

use std::borrow::Cow;
use std::ops::Range;

use toml::Spanned;
use toml::de::{DeTable, DeValue};

use crate::parse::{Result, Source};

/// The label errors in overrides carry in place of a file name.
pub(crate) const LABEL: &str = "--set";

/// Where each override lies in the spans past the file's text: override
/// `i` starts at `bases[i]`.
pub(crate) fn bases(text: &str, overrides: &[&str]) -> Vec<usize> {
    let mut at = text.len() + 1;
    overrides
        .iter()
        .map(|o| {
            let base = at;
            at += o.len() + 1;
            base
        })
        .collect()
}

/// One step of a key path: a key, and the array indices that follow it.
struct Step<'o> {
    key: &'o str,
    span: Range<usize>,
    indices: Vec<usize>,
}

/// Applies every override to `root`, in order (a later one wins).
pub(crate) fn apply<'i>(
    src: &Source<'_>,
    root: &mut DeTable<'i>,
    overrides: &[&'i str],
) -> Result<()> {
    for (i, text) in overrides.iter().enumerate() {
        let base = src.override_base(i);
        let error = |span: Range<usize>, key: &str, message: String| {
            src.error(base + span.start..base + span.end, key, message)
        };
        let Some((path, value)) = text.split_once('=') else {
            return Err(error(
                0..text.len(),
                "",
                "expected KEY=VALUE, e.g. camera.vfov=30".into(),
            ));
        };
        let steps = parse_path(path).map_err(|(span, m)| error(span, path, m))?;
        let value_at = path.len() + 1;
        let mut value = DeValue::parse(value).map_err(|e| {
            let span = e.span().unwrap_or(0..value.len());
            error(
                value_at + span.start..value_at + span.end,
                path.trim(),
                format!("invalid TOML value: {}", e.message().trim()),
            )
        })?;
        shift(&mut value, base + value_at);
        let steps: Vec<Step<'_>> = steps
            .into_iter()
            .map(|s| Step {
                span: base + s.span.start..base + s.span.end,
                ..s
            })
            .collect();
        set(src, root, &steps, value, String::new())?;
    }
    Ok(())
}

/// `a.b[0].c` as steps, with the spans of their keys in `path`.
fn parse_path(path: &str) -> std::result::Result<Vec<Step<'_>>, (Range<usize>, String)> {
    let mut steps = Vec::new();
    let mut at = 0;
    for part in path.split('.') {
        let span = at..at + part.len();
        at += part.len() + 1;
        let (key, mut rest) = part.split_at(part.find('[').unwrap_or(part.len()));
        let key_ok = !key.is_empty()
            && key
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
        if !key_ok {
            return Err((
                span,
                format!(
                    "`{path}` is not a dotted key path such as camera.vfov or lights[0].radiance"
                ),
            ));
        }
        let mut indices = Vec::new();
        while let Some(r) = rest.strip_prefix('[') {
            let (index, after) = r.split_once(']').unwrap_or((r, ""));
            let Ok(index) = index.trim().parse::<usize>() else {
                return Err((
                    span,
                    format!("`{part}`: an index is a number in brackets, as in lights[0]"),
                ));
            };
            indices.push(index);
            rest = after;
        }
        if !rest.is_empty() {
            return Err((span, format!("`{part}`: unexpected `{rest}`")));
        }
        steps.push(Step { key, span, indices });
    }
    Ok(steps)
}

/// Puts `value` at `steps` below `table` (whose dotted path is `path`),
/// making the tables on the way that the file lacks.
fn set<'i>(
    src: &Source<'_>,
    table: &mut DeTable<'i>,
    steps: &[Step<'i>],
    value: Spanned<DeValue<'i>>,
    path: String,
) -> Result<()> {
    let step = &steps[0];
    let mut here = if path.is_empty() {
        step.key.to_owned()
    } else {
        format!("{path}.{}", step.key)
    };
    let last = steps.len() == 1;
    if last && step.indices.is_empty() {
        let key = Spanned::new(step.span.clone(), Cow::Borrowed(step.key));
        // An existing key keeps its place (the map's key compares by name).
        table.remove(step.key);
        table.insert(key, value);
        return Ok(());
    }
    if table.get(step.key).is_none() {
        if !step.indices.is_empty() {
            return Err(src.error(
                step.span.clone(),
                &here,
                format!("the scene has no `{here}` to index"),
            ));
        }
        let key = Spanned::new(step.span.clone(), Cow::Borrowed(step.key));
        let empty = Spanned::new(step.span.clone(), DeValue::Table(DeTable::new()));
        table.insert(key, empty);
    }
    let mut slot = table.get_mut(step.key).expect("present or inserted");
    for (k, &index) in step.indices.iter().enumerate() {
        let DeValue::Array(items) = slot.get_mut() else {
            return Err(src.error(
                step.span.clone(),
                &here,
                format!("`{here}` is not an array: it cannot be indexed"),
            ));
        };
        let len = items.len();
        let Some(item) = items.get_mut(index) else {
            return Err(src.error(
                step.span.clone(),
                &format!("{here}[{index}]"),
                format!("index {index} is out of range: `{here}` has {len} entries"),
            ));
        };
        here = format!("{here}[{index}]");
        if last && k + 1 == step.indices.len() {
            *item = value;
            return Ok(());
        }
        slot = item;
    }
    match slot.get_mut() {
        DeValue::Table(t) => set(src, t, &steps[1..], value, here),
        _ => Err(src.error(
            step.span.clone(),
            &here,
            format!("`{here}` is not a table: it has no keys to set"),
        )),
    }
}

/// Moves every span of `v` by `offset`: from the override's own text to
/// where that text lies past the file's.
fn shift(v: &mut Spanned<DeValue<'_>>, offset: usize) {
    let span = v.span();
    let placeholder = Spanned::new(0..0, DeValue::Boolean(false));
    let mut inner = std::mem::replace(v, placeholder).into_inner();
    match &mut inner {
        DeValue::Array(items) => {
            for item in items.iter_mut() {
                shift(item, offset);
            }
        }
        DeValue::Table(t) => {
            let old = std::mem::take(t);
            for (k, mut item) in old {
                shift(&mut item, offset);
                let ks = k.span();
                t.insert(
                    Spanned::new(ks.start + offset..ks.end + offset, k.into_inner()),
                    item,
                );
            }
        }
        _ => {}
    }
    *v = Spanned::new(span.start + offset..span.end + offset, inner);
}
