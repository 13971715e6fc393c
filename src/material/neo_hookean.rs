//! placeholder, replaced on the material branch
#[derive(Debug)]
pub struct NeoHookean;
