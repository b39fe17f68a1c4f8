//! Errors that point at the offending text of a scene file.

use std::ops::Range;

use annotate_snippets::{AnnotationKind, Level, Renderer, Snippet};

/// A scene file that cannot be turned into a scene. It names the file, the
/// line and column, and the key (as a dotted path such as
/// `objects[2].shape.radius`), and its `Display` shows the offending line
/// with a caret under the value.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{rendered}")]
pub struct SceneFileError {
    /// The file's name as given by the caller.
    pub file: String,
    /// 1-based line of the offending text.
    pub line: usize,
    /// 1-based column of the offending text.
    pub column: usize,
    /// Dotted path of the offending key; empty for syntax errors.
    pub key: String,
    /// What is wrong, in one sentence.
    pub message: String,
    rendered: String,
}

impl SceneFileError {
    pub(crate) fn new(
        file: &str,
        source: &str,
        span: Range<usize>,
        key: &str,
        message: String,
    ) -> Self {
        let start = span.start.min(source.len());
        let end = span.end.clamp(start, source.len());
        let line = source[..start].matches('\n').count() + 1;
        let column = start - source[..start].rfind('\n').map_or(0, |i| i + 1) + 1;
        let title = if key.is_empty() {
            message.clone()
        } else {
            format!("`{key}`: {message}")
        };
        let report = &[Level::ERROR.primary_title(&title).element(
            Snippet::source(source)
                .line_start(1)
                .path(file)
                .fold(true)
                .annotation(AnnotationKind::Primary.span(start..end.max(start))),
        )];
        let rendered = Renderer::plain().render(report).to_string();
        SceneFileError {
            file: file.to_owned(),
            line,
            column,
            key: key.to_owned(),
            message,
            rendered,
        }
    }
}
