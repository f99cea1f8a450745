//! stub
use crate::{Error, Location, Options, Project, Report};

pub fn convert(file: &str, _stem: &str, _text: &str, _opts: &Options) -> Result<(Project, Report), Error> {
    Err(Error::at(Location::new(file, 1, 1), "not yet"))
}
