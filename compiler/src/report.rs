//! The report formats of `ferroc-report`, with the SARIF and JUnit documents given every
//! check of [`crate::checks::REGISTRY`] (their rules and test cases).

pub use ferroc_report::*;

pub mod sarif {
    pub use ferroc_report::sarif::*;

    /// One SARIF log with one run covering every checked model, every check a rule.
    pub fn document(reports: &[super::ModelReport<'_>]) -> serde_json::Value {
        ferroc_report::sarif::document(crate::checks::REGISTRY, reports)
    }
}

pub mod junit {
    /// The JUnit document: one suite per model, one test case per check.
    pub fn document(models: &[(String, super::ModelReport<'_>)], tool_errors: &[String]) -> String {
        ferroc_report::junit::document(crate::checks::REGISTRY, models, tool_errors)
    }
}
