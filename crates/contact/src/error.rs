//! Errors of the contact crate.

/// What can go wrong with contact configuration.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ContactError {
    /// Friction coefficients out of order.
    #[error(
        "friction coefficients must satisfy 0 ≤ mu_dynamic ≤ mu_static (got mu_static = {mu_static}, mu_dynamic = {mu_dynamic})"
    )]
    Friction {
        /// Static coefficient μS.
        mu_static: f64,
        /// Dynamic coefficient μD.
        mu_dynamic: f64,
    },
    /// A terrain parameter is invalid.
    #[error("terrain: {what}")]
    Terrain {
        /// What is wrong.
        what: String,
    },
}
