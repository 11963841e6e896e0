//! The AXI4-Stream port map of a streaming unit (`axis_map.json`) and the SystemVerilog wrapper
//! generated from it (`raypipe_axis_wrap.sv`): the kit's valid/ready ports on one side, a DUT
//! with `s_axis_*` / `m_axis_*` ports on the other, so a DUT with its own `tdata` layout is run
//! by the kit without packing code.
//!
//! Bit order of the default map: the DUT's input fields (every field of the input row except
//! the testbench's `class` tag) in input-file order, the first at `s_axis_tdata` bit 0, each
//! next field at the bit after the previous one, no gaps; `m_axis_tdata` likewise holds the
//! output fields in output-file order from bit 0. Both widths are rounded up to a multiple of 8
//! (AXI4-Stream carries whole bytes); the bits above the last field are 0 on `s_axis_tdata`
//! and ignored on `m_axis_tdata`. `m_axis_tuser` (the optional stage probes) carries the stage
//! row exactly as the stage file lays it out (`manifest.json` lsb of each stage field). A user
//! map (`vectors --axis-map FILE`) may place every field at any `lsb` and widen the buses.

use crate::manifest::Manifest;
use serde::{Deserialize, Serialize};

/// Map schema version.
pub const MAP_SCHEMA: u32 = 1;
/// The map's file name in a set directory.
pub const MAP_FILE: &str = "axis_map.json";
/// The wrapper's file name in a set directory.
pub const WRAP_FILE: &str = "raypipe_axis_wrap.sv";
/// The input-row field that tags a vector's coverage class for the testbench (never on `tdata`).
pub const TB_ONLY: &str = "class";

/// Where one field sits on a bus.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MapField {
    /// Field name, as in `manifest.json`.
    pub name: String,
    /// Width in bits (the manifest's).
    pub width: u32,
    /// Bus bit of the field's least significant bit.
    pub lsb: u32,
}

/// One `tdata` bus.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Bus {
    /// Bus width in bits (a multiple of 8).
    pub width: u32,
    /// The fields on it.
    pub fields: Vec<MapField>,
}

/// The stage probes on `m_axis_tuser`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Probes {
    /// Bus width in bits (the stage row's).
    pub width: u32,
    /// How the bits are laid out.
    pub layout: String,
}

/// `axis_map.json`: where each field of a unit's rows sits on the DUT's AXI4-Stream buses.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisMap {
    /// [`MAP_SCHEMA`].
    pub schema: u32,
    /// Unit (rti, slab, op, capture).
    pub unit: String,
    /// Number format.
    pub format: String,
    /// The input fields.
    pub s_axis_tdata: Bus,
    /// The output fields.
    pub m_axis_tdata: Bus,
    /// The stage probes (absent: the unit has no stage file).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub m_axis_tuser: Option<Probes>,
}

fn round8(bits: u32) -> u32 {
    bits.div_ceil(8).max(1) * 8
}

/// The input, output and stage files of a streaming set.
fn files(m: &Manifest) -> Result<[Option<&crate::manifest::File>; 3], String> {
    if !matches!(m.unit.as_str(), "rti" | "slab" | "op" | "capture") {
        return Err(format!(
            "the AXI4-Stream wrapper covers the streaming units (rti, slab, op, capture), not {}",
            m.unit
        ));
    }
    let stage = m.files.iter().find(|f| f.role == crate::hdl::STAGE_ROLE);
    Ok([m.files.first(), m.files.get(1), stage])
}

/// The default map of a set: fields packed from bit 0 in file order (see the module docs).
pub fn default_map(m: &Manifest) -> Result<AxisMap, String> {
    let [inp, out, stg] = files(m)?;
    let (inp, out) = (inp.ok_or("the set has no input file")?, out.ok_or("the set has no output file")?);
    let bus = |f: &crate::manifest::File, skip: &str| {
        let mut lsb = 0;
        let fields: Vec<MapField> = f
            .fields
            .iter()
            .filter(|x| x.name != skip)
            .map(|x| {
                let r = MapField { name: x.name.clone(), width: x.width, lsb };
                lsb += x.width;
                r
            })
            .collect();
        Bus { width: round8(lsb), fields }
    };
    Ok(AxisMap {
        schema: MAP_SCHEMA,
        unit: m.unit.clone(),
        format: m.format.clone(),
        s_axis_tdata: bus(inp, TB_ONLY),
        m_axis_tdata: bus(out, ""),
        m_axis_tuser: stg.map(|s| Probes {
            width: s.width,
            layout: format!("the stage row of {} as manifest.json lays it out (each stage field at its lsb)", s.name),
        }),
    })
}

/// Checks a (user's) map against the set: same unit and format, every DUT field of the input
/// and output files exactly once with the manifest's width, inside a bus whose width is a
/// multiple of 8, no two fields sharing a bit, and the probe width of the stage file.
pub fn check_map(map: &AxisMap, m: &Manifest) -> Result<(), String> {
    let want = default_map(m)?;
    let err = |why: String| Err(format!("{MAP_FILE}: {why}"));
    if map.schema != MAP_SCHEMA {
        return err(format!("schema {} (this raypipe reads {MAP_SCHEMA})", map.schema));
    }
    if map.unit != m.unit || map.format != m.format {
        return err(format!(
            "a map of unit {} format {}, the set is unit {} format {}",
            map.unit, map.format, m.unit, m.format
        ));
    }
    for (bus, got, want) in [
        ("s_axis_tdata", &map.s_axis_tdata, &want.s_axis_tdata),
        ("m_axis_tdata", &map.m_axis_tdata, &want.m_axis_tdata),
    ] {
        if got.width == 0 || got.width % 8 != 0 {
            return err(format!("{bus} width {} is not a positive multiple of 8", got.width));
        }
        let mut used = vec![""; got.width as usize];
        for (k, f) in got.fields.iter().enumerate() {
            if got.fields[..k].iter().any(|g| g.name == f.name) {
                return err(format!("{bus} field {} appears twice", f.name));
            }
            let Some(w) = want.fields.iter().find(|w| w.name == f.name) else {
                return err(format!("{bus} field {} is not a field of the set's {} rows", f.name, m.unit));
            };
            if f.width != w.width {
                return err(format!("{bus} field {} is {} bits wide, the set's is {}", f.name, f.width, w.width));
            }
            if f.lsb as u64 + f.width as u64 > got.width as u64 {
                return err(format!(
                    "{bus} field {} (bits {}..{}) does not fit the {}-bit bus",
                    f.name,
                    f.lsb,
                    f.lsb as u64 + f.width as u64 - 1,
                    got.width
                ));
            }
            for b in f.lsb..f.lsb + f.width {
                let other = used[b as usize];
                if !other.is_empty() {
                    return err(format!("{bus} fields {other} and {} share bit {b}", f.name));
                }
                used[b as usize] = &f.name;
            }
        }
        if let Some(w) = want.fields.iter().find(|w| !got.fields.iter().any(|f| f.name == w.name)) {
            return err(format!("{bus} has no field {}", w.name));
        }
    }
    match (&map.m_axis_tuser, &want.m_axis_tuser) {
        (Some(g), Some(w)) if g.width != w.width => {
            err(format!("m_axis_tuser width {} is not the stage row's {}", g.width, w.width))
        }
        (Some(_), None) => err("m_axis_tuser: the set has no stage signals".into()),
        (None, Some(_)) => {
            err("m_axis_tuser is missing (the set has stage signals; the probes are optional per run)".into())
        }
        _ => Ok(()),
    }
}

/// Reads and checks a map file against the set.
pub fn read_map(path: &std::path::Path, m: &Manifest) -> Result<AxisMap, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let map: AxisMap = serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    check_map(&map, m).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(map)
}

/// The map as the JSON written to [`MAP_FILE`].
pub fn map_json(map: &AxisMap) -> String {
    serde_json::to_string_pretty(map).expect("a map serialises") + "\n"
}

fn upper(name: &str) -> String {
    name.to_uppercase()
}

/// The generated SystemVerilog: package `raypipe_axis_pkg` (bus widths, each field's LSB and
/// width) and module `raypipe_axis_wrap` (the kit's valid/ready ports around the DUT named by
/// the `AXIS_DUT` macro). The map must have passed [`check_map`].
pub fn sv_wrapper(map: &AxisMap, m: &Manifest) -> Result<String, String> {
    check_map(map, m)?;
    let [inp, out, _] = files(m)?;
    let (inp, out) = (inp.expect("checked"), out.expect("checked"));
    let mut s = format!(
        "// Generated by raypipe {} ({}) from {MAP_FILE} for unit {}, format {}; see manifest.json.\n",
        m.raypipe_version, m.git, m.unit, m.format
    );
    s += "//\n// raypipe_axis_wrap: the kit's valid/ready ports (hdl/sv/raypipe_stream_tb.sv) around a DUT with\n// AXI4-Stream ports, named by the AXIS_DUT macro (hdl/run --axis MODULE sets it):\n";
    s += "//   input  aclk, aresetn (the kit's clk, rst_n: synchronous, active low)\n";
    s += &format!(
        "//   input  s_axis_tvalid, output s_axis_tready, input [{}:0] s_axis_tdata\n",
        map.s_axis_tdata.width - 1
    );
    s += &format!(
        "//   output m_axis_tvalid, input m_axis_tready, output [{}:0] m_axis_tdata\n",
        map.m_axis_tdata.width - 1
    );
    if let Some(p) = &map.m_axis_tuser {
        s += &format!(
            "//   output [{}:0] m_axis_tuser      the stage probes, with RAYPIPE_AXIS_PROBES defined\n",
            p.width - 1
        );
    }
    s += "//   input  s_axis_tlast (always 1: one vector per packet), output m_axis_tlast (ignored),\n//          with RAYPIPE_AXIS_TLAST defined\n";
    s += "//   input  [`RAYPIPE_ID_W-1:0] s_axis_tid, output m_axis_tid, with RAYPIPE_ID_W defined: results may\n//          come out in any order, matched by the id the testbench gave the vector\n";
    s += "// Where each field sits on tdata is raypipe_axis_pkg below (and axis_map.json); bits of\n// s_axis_tdata that hold no field are 0. A transfer happens at a rising edge of aclk with tvalid\n// and tready both 1; the DUT must hold m_axis_tvalid and its data until the transfer.\n";
    s += "package raypipe_axis_pkg;\n";
    s += &format!("  localparam int S_TDATA_W = {};\n", map.s_axis_tdata.width);
    s += &format!("  localparam int M_TDATA_W = {};\n", map.m_axis_tdata.width);
    s += &format!("  localparam int M_TUSER_W = {};\n", map.m_axis_tuser.as_ref().map_or(1, |p| p.width));
    for (tag, bus) in [("S", &map.s_axis_tdata), ("M", &map.m_axis_tdata)] {
        for f in &bus.fields {
            let n = upper(&f.name);
            s += &format!("  localparam int {tag}_{n}_LSB = {};\n  localparam int {tag}_{n}_W = {};\n", f.lsb, f.width);
        }
    }
    s += "endpackage\n\n";
    s += "`ifndef AXIS_DUT\n`define AXIS_DUT my_axis_dut\n`endif\n";
    s += "module raypipe_axis_wrap\n  import raypipe_set_pkg::*;\n  import raypipe_axis_pkg::*;\n(\n";
    s += "  input  logic             clk,\n  input  logic             rst_n,\n  input  logic             in_valid,\n  output logic             in_ready,\n  input  logic [IN_W-1:0]  in_row,\n  output logic             out_valid,\n  input  logic             out_ready,\n  output logic [OUT_W-1:0] out_row,\n  output logic [STG_W-1:0] stg_row\n";
    s += "`ifdef RAYPIPE_ID_W\n  ,\n  input  logic [`RAYPIPE_ID_W-1:0] in_id,\n  output logic [`RAYPIPE_ID_W-1:0] out_id\n`endif\n);\n";
    s += "  logic [S_TDATA_W-1:0] s_axis_tdata;\n  logic [M_TDATA_W-1:0] m_axis_tdata;\n  logic [M_TUSER_W-1:0] m_axis_tuser;\n";
    s += "  // the input row's fields onto s_axis_tdata\n  always @* begin\n    s_axis_tdata = '0;\n";
    for f in &map.s_axis_tdata.fields {
        let src = inp.fields.iter().find(|x| x.name == f.name).expect("checked");
        s += &format!(
            "    s_axis_tdata[{} +: {}] = in_row[{} +: {}]; // {}\n",
            f.lsb, f.width, src.lsb, src.width, f.name
        );
    }
    s += "  end\n  // m_axis_tdata's fields into the output row\n  always @* begin\n    out_row = '0;\n";
    for f in &map.m_axis_tdata.fields {
        let dst = out.fields.iter().find(|x| x.name == f.name).expect("checked");
        s += &format!(
            "    out_row[{} +: {}] = m_axis_tdata[{} +: {}]; // {}\n",
            dst.lsb, dst.width, f.lsb, f.width, f.name
        );
    }
    s += "  end\n";
    s += "`ifdef RAYPIPE_AXIS_PROBES\n  assign stg_row = STG_W'(m_axis_tuser);\n`else\n  assign m_axis_tuser = '0;\n  assign stg_row = '0;\n`endif\n";
    s += "  `AXIS_DUT dut (\n    .aclk(clk),\n    .aresetn(rst_n),\n    .s_axis_tvalid(in_valid),\n    .s_axis_tready(in_ready),\n    .s_axis_tdata(s_axis_tdata),\n";
    s += "`ifdef RAYPIPE_AXIS_TLAST\n    .s_axis_tlast(1'b1),\n    .m_axis_tlast(),\n`endif\n";
    s += "`ifdef RAYPIPE_ID_W\n    .s_axis_tid(in_id),\n    .m_axis_tid(out_id),\n`endif\n";
    s += "`ifdef RAYPIPE_AXIS_PROBES\n    .m_axis_tuser(m_axis_tuser),\n`endif\n";
    s += "    .m_axis_tvalid(out_valid),\n    .m_axis_tready(out_ready),\n    .m_axis_tdata(m_axis_tdata)\n  );\nendmodule\n";
    Ok(s)
}

/// The files `vectors --wrapper axis` adds to a set: ([`MAP_FILE`], [`WRAP_FILE`]) contents.
pub fn files_for(m: &Manifest, user_map: Option<&std::path::Path>) -> Result<Vec<(String, String)>, String> {
    let map = match user_map {
        Some(p) => read_map(p, m)?,
        None => default_map(m)?,
    };
    Ok(vec![(MAP_FILE.into(), map_json(&map)), (WRAP_FILE.into(), sv_wrapper(&map, m)?)])
}

/// `vectors --check` for a set holding a wrapper: its map passes [`check_map`] and the wrapper is
/// what this raypipe generates from that map.
pub fn check_files(dir: &std::path::Path, m: &Manifest) -> Result<(), String> {
    let (mp, wp) = (dir.join(MAP_FILE), dir.join(WRAP_FILE));
    match (mp.is_file(), wp.is_file()) {
        (false, false) => return Ok(()),
        (true, false) => return Err(format!("{MAP_FILE} without {WRAP_FILE}")),
        (false, true) => return Err(format!("{WRAP_FILE} without {MAP_FILE}")),
        _ => {}
    }
    let map = read_map(&mp, m)?;
    let want = sv_wrapper(&map, m)?;
    let got = std::fs::read_to_string(&wp).map_err(|e| format!("{}: {e}", wp.display()))?;
    if let Some((k, (a, b))) = got.lines().zip(want.lines()).enumerate().find(|(_, (a, b))| a != b) {
        return Err(format!("{WRAP_FILE} line {}: '{a}' differs from the map's '{b}'", k + 1));
    }
    if got.lines().count() != want.lines().count() {
        return Err(format!("{WRAP_FILE}: not the wrapper of its map (line count)"));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::manifest::{Field, File, Kind};

    fn field(name: &str, width: u32, lsb: u32) -> Field {
        Field {
            name: name.into(),
            dir: "in".into(),
            kind: Kind::Uint,
            width,
            lsb,
            stage: None,
            care_when: None,
            implementation_defined: false,
        }
    }

    fn file(name: &str, role: &str, fields: Vec<Field>) -> File {
        let width = fields.iter().map(|f| f.width).sum();
        File { name: name.into(), role: role.into(), rows: 1, width, digits: 1, fields, sha256: String::new() }
    }

    /// A two-field op-like set written by hand (class 8, opcode 4, a 16, b 16 → 44 bits).
    fn manifest() -> Manifest {
        let text = r#"{"schema":2,"raypipe_version":"0","git":"g","command":"c","seed":1,"count":1,"unit":"op",
            "level":1,"format":"fp16","contract":{},"options":{},"params":{},"latency":1,"stages":[],
            "acceptable_values":"","files":[],"classes":[]}"#;
        let mut m: Manifest = serde_json::from_str(text).expect("a hand-written manifest");
        m.files = vec![
            file(
                "op_inputs.hex",
                "inputs",
                vec![field("class", 8, 36), field("opcode", 4, 32), field("a", 16, 16), field("b", 16, 0)],
            ),
            file("op_expected.hex", "expected outputs", vec![field("result", 16, 1), field("cmp", 1, 0)]),
        ];
        m
    }

    #[test]
    fn default_map_packs_from_bit_zero_in_file_order_without_the_class_tag() {
        let map = default_map(&manifest()).unwrap();
        let got: Vec<(&str, u32, u32)> =
            map.s_axis_tdata.fields.iter().map(|f| (f.name.as_str(), f.width, f.lsb)).collect();
        assert_eq!(got, [("opcode", 4, 0), ("a", 16, 4), ("b", 16, 20)]);
        assert_eq!(map.s_axis_tdata.width, 40, "36 bits round up to 5 bytes");
        let got: Vec<(&str, u32)> = map.m_axis_tdata.fields.iter().map(|f| (f.name.as_str(), f.lsb)).collect();
        assert_eq!(got, [("result", 0), ("cmp", 16)]);
        assert_eq!(map.m_axis_tdata.width, 24);
        assert_eq!(map.m_axis_tuser, None);
    }

    #[test]
    fn the_wrapper_moves_each_field_between_its_row_bits_and_its_bus_bits() {
        let m = manifest();
        let w = sv_wrapper(&default_map(&m).unwrap(), &m).unwrap();
        // row bits from the manifest, bus bits from the map, written out literally
        assert!(w.contains("s_axis_tdata[0 +: 4] = in_row[32 +: 4]; // opcode"), "{w}");
        assert!(w.contains("s_axis_tdata[4 +: 16] = in_row[16 +: 16]; // a"));
        assert!(w.contains("s_axis_tdata[20 +: 16] = in_row[0 +: 16]; // b"));
        assert!(w.contains("out_row[1 +: 16] = m_axis_tdata[0 +: 16]; // result"));
        assert!(w.contains("out_row[0 +: 1] = m_axis_tdata[16 +: 1]; // cmp"));
        assert!(!w.contains("// class"), "the class tag never reaches the DUT");
        assert!(w.contains("localparam int S_TDATA_W = 40;"));
        assert!(w.contains("localparam int S_A_LSB = 4;"));
    }

    #[test]
    fn a_user_map_places_fields_anywhere_and_the_wrapper_follows_it() {
        let m = manifest();
        let mut map = default_map(&m).unwrap();
        // each operand in its own 32-bit lane, the opcode on top
        map.s_axis_tdata.width = 72;
        for f in &mut map.s_axis_tdata.fields {
            f.lsb = match f.name.as_str() {
                "a" => 0,
                "b" => 32,
                _ => 64,
            };
        }
        check_map(&map, &m).unwrap();
        let w = sv_wrapper(&map, &m).unwrap();
        assert!(w.contains("s_axis_tdata[32 +: 16] = in_row[0 +: 16]; // b"));
        assert!(w.contains("s_axis_tdata[64 +: 4] = in_row[32 +: 4]; // opcode"));
    }

    #[test]
    fn a_wrong_map_is_refused_naming_the_problem() {
        let m = manifest();
        let base = default_map(&m).unwrap();
        type Edit = Box<dyn Fn(&mut AxisMap)>;
        let cases: Vec<(Edit, &str)> = vec![
            (Box::new(|x| x.s_axis_tdata.fields[1].lsb = 0), "fields opcode and a share bit 0"),
            (Box::new(|x| x.s_axis_tdata.fields[2].lsb = 30), "does not fit the 40-bit bus"),
            (Box::new(|x| x.s_axis_tdata.width = 44), "not a positive multiple of 8"),
            (Box::new(|x| x.s_axis_tdata.fields[0].width = 5), "is 5 bits wide, the set's is 4"),
            (Box::new(|x| x.s_axis_tdata.fields.truncate(2)), "has no field b"),
            (Box::new(|x| x.s_axis_tdata.fields[0].name = "class".into()), "not a field of the set's op rows"),
            (
                Box::new(|x| {
                    let mut f = x.m_axis_tdata.fields[0].clone();
                    f.lsb = 17;
                    x.m_axis_tdata.fields.push(f)
                }),
                "field result appears twice",
            ),
            (Box::new(|x| x.format = "f32".into()), "a map of unit op format f32"),
            (
                Box::new(|x| x.m_axis_tuser = Some(Probes { width: 3, layout: String::new() })),
                "the set has no stage signals",
            ),
        ];
        for (edit, want) in cases {
            let mut map = base.clone();
            edit(&mut map);
            let e = check_map(&map, &m).unwrap_err();
            assert!(e.contains(want), "{e} (wanted: {want})");
            assert!(sv_wrapper(&map, &m).is_err());
        }
    }

    #[test]
    fn traverse_has_no_stream_wrapper() {
        let mut m = manifest();
        m.unit = "traverse".into();
        assert!(default_map(&m).unwrap_err().contains("streaming units"));
    }
}
