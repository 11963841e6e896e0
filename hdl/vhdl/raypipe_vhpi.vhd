-- raypipe's live model for VHDL testbenches (GHDL, VHPIDIRECT): the entry points of
-- hdl/vhdl/raypipe_vhpi.c. RAYPIPE_VHPI_LIB is replaced by the shared library's path when
-- hdl/vhdl/live_run compiles this file (GHDL's mcode backend loads the library by that path).
-- Encodings are VHDL integers holding the format's bits (32-bit two's complement), so formats
-- of at most 32 bits. A negative result is an error (the C ABI's code, negated; the message
-- is on stderr).
package raypipe_vhpi is
  subtype rp_name_t is string(1 to 64);
  type rp_in_t is array (0 to 63) of integer;
  type rp_out_t is array (0 to 63) of integer;
  type rp_stg_t is array (0 to 255) of integer;

  -- a unit handle: unit "rti", "slab" or "op", format and options as the CLI takes them
  function rp_vhpi_new(u, f, o : rp_name_t) return integer;
  attribute foreign of rp_vhpi_new : function is "VHPIDIRECT RAYPIPE_VHPI_LIB rp_vhpi_new";
  -- what 0: inputs a row, 1: outputs, 2: stage signals, 3: the format's width in bits
  function rp_vhpi_count(h, what : integer) return integer;
  attribute foreign of rp_vhpi_count : function is "VHPIDIRECT RAYPIPE_VHPI_LIB rp_vhpi_count";
  function rp_vhpi_out_width(h, i : integer) return integer;
  attribute foreign of rp_vhpi_out_width : function is "VHPIDIRECT RAYPIPE_VHPI_LIB rp_vhpi_out_width";
  function rp_vhpi_stage_width(h, i : integer) return integer;
  attribute foreign of rp_vhpi_stage_width : function is "VHPIDIRECT RAYPIPE_VHPI_LIB rp_vhpi_stage_width";
  -- the format's encoding of x (to nearest, ties to even)
  function rp_vhpi_encode(h : integer; x : real) return integer;
  attribute foreign of rp_vhpi_encode : function is "VHPIDIRECT RAYPIPE_VHPI_LIB rp_vhpi_encode";
  -- one test: outputs and stage signals of an input row; rc 0 or a negative code
  procedure rp_vhpi_eval(h : integer; i : rp_in_t; o : out rp_out_t; s : out rp_stg_t; rc : out integer);
  attribute foreign of rp_vhpi_eval : procedure is "VHPIDIRECT RAYPIPE_VHPI_LIB rp_vhpi_eval";

  -- functional coverage of the driven rows (docs/coverage.md): a recorder of the unit, format
  -- and options (its handle, or a negative code); each input row of unit h counted (rc 0 or a
  -- negative code); the coverage file written to a path (NUL-padded) and the recorder freed
  -- (the rows recorded, or a negative code)
  subtype rp_path_t is string(1 to 256);
  function rp_vhpi_cover_new(u, f, o : rp_name_t) return integer;
  attribute foreign of rp_vhpi_cover_new : function is "VHPIDIRECT RAYPIPE_VHPI_LIB rp_vhpi_cover_new";
  procedure rp_vhpi_cover_add(c, h : integer; i : rp_in_t; rc : out integer);
  attribute foreign of rp_vhpi_cover_add : procedure is "VHPIDIRECT RAYPIPE_VHPI_LIB rp_vhpi_cover_add";
  function rp_vhpi_cover_write(c : integer; p : rp_path_t) return integer;
  attribute foreign of rp_vhpi_cover_write : function is "VHPIDIRECT RAYPIPE_VHPI_LIB rp_vhpi_cover_write";

  -- s padded with NULs to an rp_name_t
  function rp_name(s : string) return rp_name_t;
  -- s padded with NULs to an rp_path_t
  function rp_path(s : string) return rp_path_t;
end package;

package body raypipe_vhpi is
  function rp_vhpi_new(u, f, o : rp_name_t) return integer is
  begin
    assert false report "raypipe_vhpi: the foreign library is not loaded" severity failure;
    return -1;
  end function;
  function rp_vhpi_count(h, what : integer) return integer is
  begin
    assert false report "raypipe_vhpi: the foreign library is not loaded" severity failure;
    return -1;
  end function;
  function rp_vhpi_out_width(h, i : integer) return integer is
  begin
    assert false report "raypipe_vhpi: the foreign library is not loaded" severity failure;
    return -1;
  end function;
  function rp_vhpi_stage_width(h, i : integer) return integer is
  begin
    assert false report "raypipe_vhpi: the foreign library is not loaded" severity failure;
    return -1;
  end function;
  function rp_vhpi_encode(h : integer; x : real) return integer is
  begin
    assert false report "raypipe_vhpi: the foreign library is not loaded" severity failure;
    return -1;
  end function;
  procedure rp_vhpi_eval(h : integer; i : rp_in_t; o : out rp_out_t; s : out rp_stg_t; rc : out integer) is
  begin
    assert false report "raypipe_vhpi: the foreign library is not loaded" severity failure;
  end procedure;
  function rp_vhpi_cover_new(u, f, o : rp_name_t) return integer is
  begin
    assert false report "raypipe_vhpi: the foreign library is not loaded" severity failure;
    return -1;
  end function;
  procedure rp_vhpi_cover_add(c, h : integer; i : rp_in_t; rc : out integer) is
  begin
    assert false report "raypipe_vhpi: the foreign library is not loaded" severity failure;
  end procedure;
  function rp_vhpi_cover_write(c : integer; p : rp_path_t) return integer is
  begin
    assert false report "raypipe_vhpi: the foreign library is not loaded" severity failure;
    return -1;
  end function;
  function rp_path(s : string) return rp_path_t is
    variable r : rp_path_t := (others => character'val(0));
  begin
    for k in 1 to s'length loop
      r(k) := s(s'low + k - 1);
    end loop;
    return r;
  end function;
  function rp_name(s : string) return rp_name_t is
    variable r : rp_name_t := (others => character'val(0));
  begin
    for k in 1 to s'length loop
      r(k) := s(s'low + k - 1);
    end loop;
    return r;
  end function;
end package body;
