// Reference DUT of the `traverse` unit (raypipe HDL kit): the thesis's 2-bit-per-level ray
// history traversal, restart from the root, with the slab unit (raypipe_box.sv) as the box
// tester. Behavioural and sequential: one ray at a time, one level (a left/right pair of box
// tests) per clock; its latency depends on the ray, so rays enter with a valid/ready handshake
// and results leave in ray order with res_valid (one cycle each).
//
// Tree images are written through the write port before the first ray: wr_level 8'hff is the
// root entry, otherwise level wr_level's left (wr_right = 0) or right bank at row wr_row; an
// entry is one line of tree_root.hex / tree_l<k>_<bank>.hex (box, then the address word:
// bit 31 a leaf and its id in bits 30..0, else the pair index at the next level).
// Per level and pass (hist: 00 new, 01 one child hit, 10 both hit and the nearer explored,
// 11 the farther taken): new & both hit -> nearer, 10; one hit -> it, 01; 10 & the deepest 10
// at pass start -> farther, 11, deeper levels 00; 10 otherwise -> nearer; 11 -> farther; no
// hit -> the pass ends. The right child is nearer only when its t_near < the left's.
// Define RAYPIPE_INJECT_FAULT (or RAYPIPE_FAULT_TRAVERSE_NEAR_TIE, the bank fault
// traverse.near.tie) to send ties to the right child (the negative check), and
// RAYPIPE_COUNT_PAIRS_TWICE to count box tests otherwise (passes; fails with +strict), and
// RAYPIPE_INJECT_HANG to never finish a ray of class 2 (the testbench reports each hang).
module raypipe_traverse_ref
  import raypipe_fp::*;
  import raypipe_box::*;
  import raypipe_set_pkg::*;
(
  input  logic               clk,
  input  logic               rst_n,
  input  logic               wr_en,
  input  logic [7:0]         wr_level,
  input  logic               wr_right,
  input  logic [31:0]        wr_row,
  input  logic [ENTRY_W-1:0] wr_data,
  input  logic               ray_valid,
  output logic               ray_ready,
  input  logic [IN_W-1:0]    ray_row,
  output logic               res_valid,
  output logic [OUT_W-1:0]   res_row
);
  localparam int W = WIDTH;
  localparam int D = LEVELS;
  localparam int NL = LEAVES;
  localparam int HD = D > 0 ? D : 1;

  logic [ENTRY_W-1:0] lmem [0:TOTAL_ROWS-1];
  logic [ENTRY_W-1:0] rmem [0:TOTAL_ROWS-1];
  logic [ENTRY_W-1:0] root_e;

  always @(posedge clk) begin
    if (wr_en && wr_level == 8'hff) root_e <= wr_data;
    else if (wr_en && wr_right) rmem[level_base(int'(wr_level)) + int'(wr_row)] <= wr_data;
    else if (wr_en) lmem[level_base(int'(wr_level)) + int'(wr_row)] <= wr_data;
  end

  // a field of an entry: 0..5 = minx miny minz maxx maxy maxz
  function automatic word_t ef(logic [ENTRY_W-1:0] e, int k);
    return word_t'(e[32 + (5 - k) * W +: W]);
  endfunction

  function automatic logic [64:0] box(ray_t r, logic [ENTRY_W-1:0] e);
    return test(r, ef(e, 0), ef(e, 1), ef(e, 2), ef(e, 3), ef(e, 4), ef(e, 5));
  endfunction

  // a ray input field: 0..7 = ox oy oz dx dy dz tmin tmax
  function automatic word_t rf(logic [IN_W-1:0] row, int k);
    return word_t'(row[(7 - k) * W +: W]);
  endfunction

  typedef enum logic [1:0] {IDLE, ROOT, LEVEL, DONE} state_e;
  state_e state;
  logic [7:0] ray_class;
  ray_t ray;
  logic [1:0] hist [0:HD-1];
  logic [31:0] leaves [0:NL-1];
  int count, passes, box_tests, level, idx, resume;

  assign ray_ready = rst_n && state == IDLE;

  function automatic int deepest_split();
    int k = -1;
    for (int l = 0; l < D; l++) if (hist[l] == 2'b10) k = l;
    return k;
  endfunction

  // near / far side when both hit: right (1) only when its entry is less than the left's
  function automatic logic right_nearer(word_t tl, word_t tr);
`ifdef RAYPIPE_FAULT_TRAVERSE_NEAR_TIE
    return fle(F, tr, tl);  // injected fault: ties go right
`elsif RAYPIPE_INJECT_FAULT
    return fle(F, tr, tl);  // the same fault under the kit's older name
`else
    return flt(F, tr, tl);
`endif
  endfunction

  task automatic start_pass;
    passes = passes + 1;
    resume = deepest_split();
    level = 0;
    idx = 0;
  endtask

  task automatic end_pass;
    if (count == NL || deepest_split() < 0) state = DONE;
    else start_pass();
  endtask

  always @(posedge clk) begin
    logic [64:0] el, er;
    logic [31:0] a;
    int side;
    res_valid = 1'b0;
    if (!rst_n) begin
      state = IDLE;
    end else begin
      case (state)
        IDLE:
        if (ray_valid) begin
          ray = setup(rf(ray_row, 0), rf(ray_row, 1), rf(ray_row, 2), rf(ray_row, 3), rf(ray_row, 4), rf(ray_row, 5),
                      rf(ray_row, 6), rf(ray_row, 7));
          ray_class = ray_row[IN_W-1 -: 8];
          for (int l = 0; l < HD; l++) hist[l] = 2'b00;
          for (int i = 0; i < NL; i++) leaves[i] = 0;
          count = 0;
          passes = 0;
          box_tests = 0;
          state = ROOT;
        end
        ROOT: begin
          box_tests = 1;
          el = box(ray, root_e);
          a = root_e[31:0];
          if (!el[64]) state = DONE;
          else if (a[31]) begin
            passes = 1;
            leaves[0] = {1'b0, a[30:0]};
            count = 1;
            state = DONE;
          end else begin
            start_pass();
            state = LEVEL;
          end
        end
        LEVEL: begin
`ifdef RAYPIPE_COUNT_PAIRS_TWICE
          // counts its box tests otherwise (implementation-defined: passes unless +strict)
          box_tests = box_tests + 4;
`else
          box_tests = box_tests + 2;
`endif
          el = box(ray, lmem[level_base(level) + idx]);
          er = box(ray, rmem[level_base(level) + idx]);
          side = -1;
          if (el[64] && er[64]) begin
            if (hist[level] == 2'b00) begin
              hist[level] = 2'b10;
              side = right_nearer(el[63:0], er[63:0]);
            end else if (hist[level] == 2'b10 && level == resume) begin
              hist[level] = 2'b11;
              for (int l = level + 1; l < D; l++) hist[l] = 2'b00;
              side = !right_nearer(el[63:0], er[63:0]);
            end else if (hist[level] == 2'b10) side = right_nearer(el[63:0], er[63:0]);
            else if (hist[level] == 2'b11) side = !right_nearer(el[63:0], er[63:0]);
          end else if ((el[64] || er[64]) && (hist[level] == 2'b00 || hist[level] == 2'b01)) begin
            hist[level] = 2'b01;
            side = er[64];
          end
          if (side < 0) end_pass();
          else begin
            a = side == 1 ? rmem[level_base(level) + idx][31:0] : lmem[level_base(level) + idx][31:0];
            if (a[31]) begin
              leaves[count] = {1'b0, a[30:0]};
              count = count + 1;
              end_pass();
            end else begin
              idx = int'(a);
              level = level + 1;
            end
          end
        end
        DONE: begin
`ifdef RAYPIPE_INJECT_HANG
          // the kit's hang check: a ray of class 2 (miss) never finishes
          if (ray_class == 8'd2) state = DONE;
          else begin
`endif
          res_row = '0;
          res_row[2 * D + 48 + 32 * NL +: 8] = count[7:0];
          for (int i = 0; i < NL; i++) res_row[2 * D + 48 + 32 * (NL - 1 - i) +: 32] = leaves[i];
          res_row[2 * D + 32 +: 16] = passes[15:0];
          res_row[2 * D +: 32] = box_tests;
          for (int l = 0; l < D; l++) res_row[2 * (D - 1 - l) +: 2] = hist[l];
          res_valid = 1'b1;
          state = IDLE;
`ifdef RAYPIPE_INJECT_HANG
          end
`endif
        end
      endcase
    end
  end
endmodule
