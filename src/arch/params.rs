//! The parameters of the thesis hardware (chapters 4 and 5), each with the thesis's value as
//! its default where the thesis gives one, and the source of every other default.

use serde::{Deserialize, Serialize};

/// The machine the throughput model describes: the RTI accelerator (n pipelines fed from
/// interleaved ray packet buffers, triangles streamed from DRAM and broadcast) and the traversal
/// core (back-to-back level pipelines, 2 BVI pipelines each, rays recirculated for restarts).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ArchParams {
    /// RTI pipelines n (no thesis value; figure 3-3 sweeps several).
    pub pipelines: u32,
    /// Ray packet buffers interleaved on the pipelines (thesis ch. 4: 4).
    pub buffers: u32,
    /// Cycles to assemble one triangle from DRAM words (thesis ch. 4: 3 on the Novo-G).
    pub tri_assemble: u32,
    /// Cycles to broadcast an assembled triangle to the pipelines (thesis ch. 4: 1).
    pub tri_broadcast: u32,
    /// RTI pipeline latency in cycles, ray and triangle in to min-capture updated (no thesis
    /// value; default 10, one cycle per stage of the modelled datapath with the reciprocal,
    /// `datapath::rti::stage_count`).
    pub rti_latency: u32,
    /// RTI clock in MHz (thesis ch. 4: 100).
    pub rti_mhz: f64,
    /// DRAM bytes per RTI cycle for rays and results (default 12: a 36-byte triangle in the
    /// thesis's 3 cycles).
    pub dram_bytes_per_cycle: u32,
    /// Bytes of one ray in DRAM (default 36: the thesis's 72 bytes per ray–triangle pair less a
    /// 36-byte triangle of nine binary32 coordinates).
    pub ray_bytes: u32,
    /// Bytes of one result in DRAM (no thesis value; default 16: t, u, v and a triangle index).
    pub result_bytes: u32,
    /// Loads of the next packet's rays and stores of the last packet's results overlap the
    /// triangle stream (the thesis loads, then streams, then stores: default off).
    pub overlap_io: bool,
    /// Level pipelines of the traversal core L (default 32: the thesis's "25 to 32 levels").
    pub levels: u32,
    /// Rays entering the traversal core per cycle (1; the thesis's dual-port BRAM proposal: 2).
    pub ports: u32,
    /// Cycles a ray spends in one level pipeline: BVI (6 subtracts, 6 multiplies), compare and
    /// history update (no thesis value; default 16).
    pub level_latency: u32,
    /// Traversal clock in MHz (thesis ch. 5: 200).
    pub trav_mhz: f64,
    /// BRAM bits of one stored box (default 192: six binary32 coordinates).
    pub box_bits: u32,
    /// BRAM bits of one child address word (default 32).
    pub addr_bits: u32,
}

impl Default for ArchParams {
    fn default() -> Self {
        ArchParams {
            pipelines: 16,
            buffers: 4,
            tri_assemble: 3,
            tri_broadcast: 1,
            rti_latency: datapath::rti::stage_count(datapath::format::DivMode::RecipMul) as u32,
            rti_mhz: 100.0,
            dram_bytes_per_cycle: 12,
            ray_bytes: 36,
            result_bytes: 16,
            overlap_io: false,
            levels: 32,
            ports: 1,
            level_latency: 16,
            trav_mhz: 200.0,
            box_bits: 192,
            addr_bits: 32,
        }
    }
}

impl ArchParams {
    /// Cycles between two triangles reaching the pipelines: assembly then broadcast.
    pub fn cadence(&self) -> u64 {
        (self.tri_assemble + self.tri_broadcast) as u64
    }

    /// Ray buffers that get a cycle of each triangle: min(buffers, cadence) (a buffer beyond
    /// the cadence finds no free cycle).
    pub fn buffers_used(&self) -> u64 {
        (self.buffers as u64).min(self.cadence())
    }

    /// Rays in one round of a leaf: n pipelines times the buffers used.
    pub fn packet(&self) -> u64 {
        self.pipelines as u64 * self.buffers_used()
    }

    /// The RTI accelerator's peak: n tests per cycle when every cycle of the cadence has a
    /// buffer, in tests per second.
    pub fn rti_peak(&self) -> f64 {
        self.pipelines as f64 * self.rti_mhz * 1e6 * self.buffers_used() as f64 / self.cadence() as f64
    }

    /// BRAM bits of `boxes` stored box entries (a box and an address word each).
    pub fn bram_bits(&self, boxes: u64) -> u64 {
        boxes * (self.box_bits + self.addr_bits) as u64
    }

    /// Refuses a parameter set the model cannot evaluate (a clear message naming the flag).
    pub fn check(&self) -> Result<(), String> {
        let positive = [
            ("--pipelines", self.pipelines),
            ("--buffers", self.buffers),
            ("--dram-bytes", self.dram_bytes_per_cycle),
            ("--ray-bytes", self.ray_bytes),
            ("--result-bytes", self.result_bytes),
            ("--levels", self.levels),
            ("--ports", self.ports),
        ];
        for (flag, v) in positive {
            if v == 0 {
                return Err(format!("{flag} must be at least 1"));
            }
        }
        if self.tri_assemble + self.tri_broadcast == 0 {
            return Err("--tri-assemble plus --tri-broadcast must be at least 1 cycle".into());
        }
        for (flag, v) in [("--rti-mhz", self.rti_mhz), ("--trav-mhz", self.trav_mhz)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("{flag} must be a positive clock in MHz, got {v}"));
            }
        }
        Ok(())
    }
}
