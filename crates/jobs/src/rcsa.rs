//! The RCSA job (`chatter rcsa`, `chatter.rcsa`): the tool-tip FRF of a tool-holder-spindle
//! assembly by receptance coupling (Schmitz et al. 2022, seed 004, Eq. 1-4; [`chatter_rcsa`]).

use crate::error::Result;
use chatter_frf::Frf;
use chatter_rcsa::Assembly;
use std::path::Path;

/// The request of an RCSA job: a validated assembly (segments, connection, spindle, band; the
/// checks are those of [`Assembly::from_file`], once).
#[derive(Debug, Clone, PartialEq)]
pub struct RcsaRequest {
    /// The assembly.
    pub assembly: Assembly,
}

impl RcsaRequest {
    /// The request of an assembly file (JSON, see `chatter_rcsa::assembly`); measured FRFs are
    /// read relative to its folder.
    pub fn from_path(path: &Path) -> Result<Self> {
        Ok(Self {
            assembly: Assembly::from_path(path)?,
        })
    }
}

/// The outcome of an RCSA job.
#[derive(Debug, Clone, PartialEq)]
pub struct RcsaOutcome {
    /// The tool-tip receptance h(G11) over the assembly's band (m/N).
    pub tool_tip: Frf,
}

impl RcsaOutcome {
    /// The tool-tip FRF in the columns of `chatter frf`
    /// (`frequency_hz,real_m_per_n,imag_m_per_n,magnitude_m_per_n`).
    pub fn to_csv(&self) -> String {
        chatter_frf::text::to_csv(&self.tool_tip)
    }
}

/// Couple the assembly (004 Eq. 1-4) and return the tool-tip FRF.
pub fn rcsa(request: &RcsaRequest) -> Result<RcsaOutcome> {
    Ok(RcsaOutcome {
        tool_tip: request.assembly.tool_tip_frf()?,
    })
}
