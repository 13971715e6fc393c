//! placeholder, replaced on the material branch
