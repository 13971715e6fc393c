//! Run outputs (placeholder, replaced on the output branch).
