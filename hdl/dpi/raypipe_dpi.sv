// raypipe's live reference model for SystemVerilog testbenches: DPI-C imports of the C ABI
// (capi/include/raypipe.h, docs/capi.md). Link the simulation with capi's library
// (target/release/libraypipe_capi.a -lpthread -ldl -lm, or -lraypipe_capi).
//
// Rows are the vector files' rows: every value is a format encoding in the low bits of a
// 64-bit word (flags 0 or 1). Every function returns 0 (RP_OK) or an error code;
// rp_last_error() says what went wrong. A handle is a chandle from rp_unit_new.
package raypipe_dpi;
  localparam int RP_OK = 0;
  localparam int RP_ERR_ARGUMENT = 1;
  localparam int RP_ERR_NULL = 2;
  localparam int RP_ERR_ALIGN = 3;
  localparam int RP_ERR_LENGTH = 4;
  localparam int RP_ERR_UNIT = 5;
  localparam int RP_ERR_INTERNAL = 6;
  // the largest rows these imports pass (rti: 17 inputs, 5 outputs; stage rows up to 256)
  localparam int RP_MAX_IN = 32;
  localparam int RP_MAX_OUT = 8;
  localparam int RP_MAX_STG = 256;

  import "DPI-C" function string rp_version();
  import "DPI-C" function string rp_last_error();
  // unit: "rti", "slab" or "op"; format and options as the CLI takes them
  import "DPI-C" function int rp_unit_new(input string unit, input string format, input string options,
                                          output chandle u);
  import "DPI-C" function void rp_unit_free(input chandle u);
  import "DPI-C" function longint unsigned rp_unit_inputs(input chandle u);
  import "DPI-C" function longint unsigned rp_unit_outputs(input chandle u);
  import "DPI-C" function longint unsigned rp_unit_stages(input chandle u);
  import "DPI-C" function int unsigned rp_unit_width(input chandle u);
  import "DPI-C" function int unsigned rp_unit_output_width(input chandle u, input longint unsigned i);
  import "DPI-C" function int unsigned rp_unit_stage_width(input chandle u, input longint unsigned i);
  import "DPI-C" function string rp_unit_stage_name(input chandle u, input longint unsigned i);
  // one test: n_inputs values in, outputs and (n_stages > 0) stage signals out
  import "DPI-C" function int rp_eval(input chandle u, input longint unsigned inputs[RP_MAX_IN],
                                      input longint unsigned n_inputs, output longint unsigned outputs[RP_MAX_OUT],
                                      input longint unsigned n_outputs, output longint unsigned stages[RP_MAX_STG],
                                      input longint unsigned n_stages);
  // functional coverage of the driven rows (docs/coverage.md): a recorder of the unit, format and
  // options; each input row counted with the model's outputs and stage signals; written as a
  // coverage file `raypipe cover` reads and merges
  import "DPI-C" function int rp_cover_new(input string unit, input string format, input string options,
                                           output chandle c);
  import "DPI-C" function int rp_cover_add(input chandle c, input longint unsigned inputs[RP_MAX_IN],
                                           input longint unsigned n_inputs);
  import "DPI-C" function longint unsigned rp_cover_rows(input chandle c);
  import "DPI-C" function int rp_cover_write(input chandle c, input string path);
  import "DPI-C" function void rp_cover_free(input chandle c);
  // the format's encoding of a real (to nearest, ties to even), and back
  import "DPI-C" function int rp_encode(input chandle u, input real x, output longint unsigned bits);
  import "DPI-C" function int rp_decode(input chandle u, input longint unsigned bits, output real x);
endpackage
