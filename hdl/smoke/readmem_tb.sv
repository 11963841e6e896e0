// Smoke test of a generated vector set in Icarus Verilog: the generated package compiles, the
// rti input file loads with $readmemh into rows of the package's width, and the fields sliced
// through the packed struct are the ones the manifest describes (vector 2 is the first of
// class 1 when the set was written with --count 2). Not the testbench kit (issue 5).
// Run: raypipe vectors --unit rti --format e8m16 --count 2 --out set
//      iverilog -g2012 -o tb set/raypipe_pkg.sv hdl/smoke/readmem_tb.sv && vvp tb
module readmem_tb;
  import raypipe_rti_pkg::*;
  logic [RTI_INPUTS_W-1:0] mem [0:23];
  rti_inputs_t row;
  initial begin
    $readmemh("set/rti_inputs.hex", mem);
    row = mem[2];
    if (row.class_id !== 8'd1) $fatal(1, "class of vector 2 is %0d, expected 1", row.class_id);
    row = mem[23];
    if (row.class_id !== 8'd11) $fatal(1, "class of vector 23 is %0d, expected 11", row.class_id);
    $display("1 passed, 0 failed");
    $finish;
  end
endmodule
