//! A per-lot override (issue 61): one edit of one lot's field, as the overrides table
//! `[input] overrides` holds it (`input::overrides` reads and applies them) and as the
//! workbench keeps its unsaved edits in memory (`InputParams::rows`).

/// One edit: lot `lot`'s `field` is `value`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Override {
    /// The lot's id (a multipart lot's record id reaches every part).
    pub lot: String,
    /// A role of [`ROLES`] or an attribute name.
    pub field: String,
    /// The new value; "" for a role clears it (a type drawn again, no district).
    pub value: String,
    /// The row in the file (the header is row 1).
    pub row: usize,
}
