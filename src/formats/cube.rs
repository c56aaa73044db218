//! Gaussian cube files (see GUIDE §3). Placeholder: being written.
use std::path::Path;

use super::LoadError;
use crate::model::Document;

pub fn load(path: &Path) -> Result<Document, LoadError> {
    let text = super::read_text(path)?;
    parse(&path.display().to_string(), &text).map_err(LoadError::from)
}

pub fn parse(_file: &str, _text: &str) -> Result<Document, super::ParseError> {
    todo!()
}
