-- api_generic.lua: one table of every function of the Lua API, driven by one test each
-- for two promises of docs/lua-api.md: an options table refuses a key it does not know
-- (naming it), and every number a function takes, positional, in an option or inside a
-- vector, refuses NaN and both infinities (naming the argument or field); a refused
-- call changes nothing (w:hash()). The table is checked against the metatables'
-- method tables, so a function added to the API without a row here fails this file.
--
-- A row is one of:
--   none = "why"                 takes no number and no options table
--   args = {...}, call = fn      positional arguments; nums lists the positions (1-based,
--                                after self) holding numbers or tables of numbers
--   opts = {...}, call = fn      an options table; nums lists its keys holding numbers
--                                or tables of numbers; opts_arg its position (after self)
-- call(f, ...) makes the call on a fresh fixture f (see fixture()).

local BAD = { 0 / 0, 1 / 0, -1 / 0 }
local function badname(x) return x ~= x and "nan" or (x > 0 and "inf" or "-inf") end

local function fixture()
  local f = {}
  f.w = wobble.world{}
  f.p = f.w:particle{ pos = {0, 0, 0} }
  f.q = f.w:particle{ pos = {1, 0, 0} }
  f.c = f.w:distance(f.p, f.q)
  f.r3 = f.w:particle{ pos = {0.5, 0, 1} }
  f.r4 = f.w:particle{ pos = {0.5, 0.5, -1} }
  f.bend = f.w:bend(f.p, f.q, f.r3, f.r4)
  f.col = f.w:collider{ shape = "sphere", center = {0, -3, 0}, radius = 0.5 }
  f.body = f.w:lattice{ min = {-1, 1, -1}, max = {1, 3, 1}, res = {2, 2, 2} }
  f.vol = f.w:volume(f.body.first, f.body.first + 1, f.body.first + 2, f.body.first + 4)
  f.m = wobble.mesh{ vertices = {{-0.5, 1.5, -0.5}, {0.5, 1.5, -0.5}, {0, 2.5, 0.5}, {0, 1.5, 0.5}},
                     triangles = {{1, 3, 2}, {1, 2, 4}, {1, 4, 3}, {2, 3, 4}} }
  f.skin = f.w:skin(f.m, f.body)
  f.sm = f.w:shape_match(f.body, { stiffness = 0.5 })
  f.pr = f.w:pressure(f.body)
  f.r = wobble.renderer{ width = 8, height = 8, backend = "null" }
  f.rec = f.w:record_vtk("api_generic/rec")
  f.att = f.w:attach(f.p, f.col)
  f.grab = f.w:grab(f.q, {1, 0, 0})
  f.rb = f.w:rigid{ shape = "box", half = {0.2, 0.2, 0.2}, pos = {0, 6, 0} }
  return f
end

local link_nums = { "compliance", "damping", "yield", "creep", "break_strain", "break_force" }
-- the link options every builder takes, valid values
local function link(t) t.compliance, t.damping, t.yield, t.creep, t.break_strain, t.break_force = 0, 0, 0.1, 1, 1, 1e3
  t.collide, t.self_collide, t.friction = true, false, 0 return t end
local function plus(t, extra) local r = {} for _, v in ipairs(t) do r[#r + 1] = v end
  for _, v in ipairs(extra) do r[#r + 1] = v end return r end

local CASES = {
  -- ---- wobble.*
  ["wobble.world"] = { opts = { gravity = {0, -9.81, 0}, dt = 1 / 60, substeps = 2, iterations = 1, damping = 0,
                                relaxation = 1, threads = 1, contacts = true, tolerance = 0 },
                       nums = { "gravity", "dt", "substeps", "iterations", "damping", "relaxation", "threads", "tolerance" },
                       call = function(_, o) return wobble.world(o) end },
  ["wobble.renderer"] = { opts = { width = 8, height = 8, samples = 1, backend = "null" },
                          nums = { "width", "height", "samples" },
                          call = function(_, o) return wobble.renderer(o) end },
  ["wobble.camera"] = { opts = { eye = {0, 1, 4}, target = {0, 1, 0}, up = {0, 1, 0}, fov = 40 },
                        nums = { "eye", "target", "up", "fov" },
                        call = function(_, o) return wobble.camera(o) end },
  ["wobble.mesh"] = { opts = { vertices = {0, 0, 0, 1, 0, 0, 0, 1, 0}, triangles = {1, 2, 3}, weld = 0.001 },
                      nums = { "vertices", "triangles", "weld" },
                      call = function(_, o) return wobble.mesh(o) end },
  ["wobble.load_mesh"] = { opts = { scale = 1, weld = 0.001, timeout = 10 }, opts_arg = 2,
                           nums = { "scale", "weld", "timeout" },
                           call = function(_, o) return wobble.load_mesh("../../assets/rounded_cube.obj", o) end },
  ["wobble.read_frame"] = { args = { "api_generic/none.mp4", 0 }, nums = { 2 },
                            call = function(_, ...) return wobble.read_frame(...) end },
  ["wobble.load"] = { none = "a path" },
  ["wobble.probe"] = { none = "a path" },
  ["wobble.read_png"] = { none = "a path" },
  ["wobble.clock"] = { none = "no arguments" },
  ["wobble.result"] = { none = "any keys; a NaN is a result to report (tests/cli/sweep.sh)" },

  -- ---- world: options
  ["world:particle"] = { opts = { pos = {0, 0, 0}, vel = {0, 0, 0}, mass = 1, radius = 0.02, group = 0, friction = 0 },
                         nums = { "pos", "vel", "mass", "radius", "group", "friction" },
                         call = function(f, o) return f.w:particle(o) end },
  ["world:distance"] = { opts = { compliance = 0, rest = 1, damping = 0, yield = 0.1, creep = 1, break_strain = 1,
                                  break_force = 1e3 },
                         opts_arg = 3, nums = plus(link_nums, { "rest" }),
                         call = function(f, o) return f.w:distance(f.p, f.q, o) end },
  ["world:bend"] = { opts = { compliance = 0, damping = 0, rest = 0.5, break_torque = 10 }, opts_arg = 5,
                     nums = { "compliance", "damping", "rest", "break_torque" },
                     call = function(f, o) return f.w:bend(f.p, f.q, f.r3, f.r4, o) end },
  ["world:cloth"] = { opts = link{ origin = {0, 0, 0}, size = {1, 1}, res = {2, 2}, mass = 1, radius = 0.02, bend = 0,
                                  bend_links = 0 },
                      nums = plus(link_nums, { "origin", "size", "res", "mass", "radius", "bend", "bend_links", "friction" }),
                      call = function(f, o) return f.w:cloth(o) end },
  ["world:rope"] = { opts = link{ from = {0, 0, 0}, to = {1, 0, 0}, segments = 2, mass = 1, radius = 0.02 },
                     nums = plus(link_nums, { "from", "to", "segments", "mass", "radius", "friction" }),
                     call = function(f, o) return f.w:rope(o) end },
  ["world:lattice"] = { opts = link{ min = {0, 0, 0}, max = {1, 1, 1}, res = {2, 2, 2}, mass = 1, radius = 0.02,
                                     tets = true, volume_compliance = 0, young = 1e5, poisson = 0.3 },
                        nums = plus(link_nums, { "min", "max", "res", "mass", "radius", "friction", "volume_compliance",
                                                 "young", "poisson" }),
                        call = function(f, o) return f.w:lattice(o) end },
  ["world:from_mesh"] = { opts = link{ mass = 1, radius = 0.02, target = 4, neighbours = 3 }, opts_arg = 2,
                          nums = plus(link_nums, { "mass", "radius", "target", "neighbours", "friction" }),
                          call = function(f, o) return f.w:from_mesh(f.m, o) end },
  ["world:skin"] = { opts = { bones = 2, neighbours = 4, iterations = 2 }, opts_arg = 3,
                     nums = { "bones", "neighbours", "iterations" },
                     call = function(f, o) return f.w:skin(f.m, f.body, o) end },
  ["world:shape_match"] = { opts = { stiffness = 0.5, yield = 0.1, creep = 1 }, opts_arg = 2,
                            nums = { "stiffness", "yield", "creep" },
                            call = function(f, o) return f.w:shape_match(f.body, o) end },
  ["world:pressure"] = { opts = { pressure = 1.5, compliance = 0 }, opts_arg = 2, nums = { "pressure", "compliance" },
                         call = function(f, o) return f.w:pressure(f.body, o) end },
  ["world:run"] = { opts = { frames = 1, seconds = 0.1 }, nums = { "frames", "seconds" },
                    call = function(f, o) return f.w:run(o) end },
  ["world:record_pc2"] = { opts = { particles = {1, 2}, every = 1 }, opts_arg = 2, nums = { "particles", "every" },
                           call = function(f, o) return f.w:record_pc2("api_generic/p.pc2", o) end },
  ["world:record_vtk"] = { opts = { every = 1 }, opts_arg = 2, nums = { "every" },
                           call = function(f, o) return f.w:record_vtk("api_generic/v", o) end },
  -- colliders: one row per shape (a key of another shape is unknown there)
  ["world:collider"] = {
    shapes = {
      { shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0, restitution = 0 },
      { shape = "sphere", center = {0, 0, 0}, radius = 1, friction = 0, restitution = 0 },
      { shape = "box", center = {0, 0, 0}, half = {1, 1, 1}, rotation = {1, 0, 0, 0}, friction = 0, restitution = 0 },
      { shape = "capsule", a = {0, 0, 0}, b = {1, 0, 0}, radius = 1, friction = 0, restitution = 0 },
      { shape = "mesh", mesh = wobble.mesh{ vertices = {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}}, triangles = {{1, 3, 2}} },
        center = {0, 0, 0}, rotation = {1, 0, 0, 0}, scale = 1, friction = 0, restitution = 0 },
    },
    call = function(f, o) return f.w:collider(o) end },
  -- rigid bodies: one row per shape
  ["world:rigid"] = {
    shapes = {
      { shape = "sphere", radius = 0.5, mass = 1, pos = {0, 0, 0}, rotation = {1, 0, 0, 0}, vel = {0, 0, 0},
        angular_velocity = {0, 0, 0}, friction = 0, restitution = 0 },
      { shape = "box", half = {1, 1, 1}, mass = 1, pos = {0, 0, 0}, rotation = {1, 0, 0, 0}, vel = {0, 0, 0},
        angular_velocity = {0, 0, 0}, friction = 0, restitution = 0 },
      { shape = "capsule", a = {0, 0, 0}, b = {1, 0, 0}, radius = 0.5, mass = 1, pos = {0, 0, 0},
        rotation = {1, 0, 0, 0}, vel = {0, 0, 0}, angular_velocity = {0, 0, 0}, friction = 0, restitution = 0 },
    },
    call = function(f, o) return f.w:rigid(o) end },

  -- ---- world: positional numbers
  ["world:set_position"] = { args = { 1, 0, 0, 0 }, nums = { 1, 2, 3, 4 },
                             call = function(f, ...) return f.w:set_position(...) end },
  ["world:set_velocity"] = { args = { 1, 0, 0, 0 }, nums = { 1, 2, 3, 4 },
                             call = function(f, ...) return f.w:set_velocity(...) end },
  ["world:set_gravity"] = { args = { 0, -1, 0 }, nums = { 1, 2, 3 },
                            call = function(f, ...) return f.w:set_gravity(...) end },
  ["world:pin"] = { args = { 1, {0, 0, 0} }, nums = { 1, 2 }, call = function(f, ...) return f.w:pin(...) end },
  ["world:unpin"] = { args = { 1 }, nums = { 1 }, call = function(f, ...) return f.w:unpin(...) end },
  ["world:pinned"] = { args = { 1 }, nums = { 1 }, call = function(f, ...) return f.w:pinned(...) end },
  ["world:position"] = { args = { 1 }, nums = { 1 }, call = function(f, ...) return f.w:position(...) end },
  ["world:velocity"] = { args = { 1 }, nums = { 1 }, call = function(f, ...) return f.w:velocity(...) end },
  ["world:mass"] = { args = { 1 }, nums = { 1 }, call = function(f, ...) return f.w:mass(...) end },
  ["world:radius"] = { args = { 1 }, nums = { 1 }, call = function(f, ...) return f.w:radius(...) end },
  ["world:friction"] = { args = { 1 }, nums = { 1 }, call = function(f, ...) return f.w:friction(...) end },
  ["world:group"] = { args = { 1 }, nums = { 1 }, call = function(f, ...) return f.w:group(...) end },
  ["world:set_self_collide"] = { args = { 1, true }, nums = { 1 }, call = function(f, ...) return f.w:set_self_collide(...) end },
  ["world:set_dt"] = { args = { 0.01 }, nums = { 1 }, call = function(f, ...) return f.w:set_dt(...) end },
  ["world:set_tolerance"] = { args = { 1e-4 }, nums = { 1 }, call = function(f, ...) return f.w:set_tolerance(...) end },
  ["world:set_substeps"] = { args = { 2 }, nums = { 1 }, call = function(f, ...) return f.w:set_substeps(...) end },
  ["world:set_iterations"] = { args = { 2 }, nums = { 1 }, call = function(f, ...) return f.w:set_iterations(...) end },
  ["world:set_damping"] = { args = { 0 }, nums = { 1 }, call = function(f, ...) return f.w:set_damping(...) end },
  ["world:set_relaxation"] = { args = { 1 }, nums = { 1 }, call = function(f, ...) return f.w:set_relaxation(...) end },
  ["world:set_threads"] = { args = { 1 }, nums = { 1 }, call = function(f, ...) return f.w:set_threads(...) end },
  ["world:set_solver"] = { none = "a solver name" },
  ["world:load_particles"] = { none = "a path" },
  ["world:save"] = { none = "a path" },
  ["world:save_vtp"] = { none = "a path" },
  ["world:close"] = { none = "no arguments" },
  -- volume constraints and tet solids (lua/volume.c); from_mesh's tets options: volume_io.lua
  ["world:volume"] = { opts = { compliance = 0, rest = 0.5 }, opts_arg = 5, nums = { "compliance", "rest" },
                       call = function(f, o) local b = f.body.first
                         return f.w:volume(b, b + 1, b + 2, b + 4, o) end },
  ["world:volume_info"] = { args = { 1 }, nums = { 1 }, call = function(f, ...) return f.w:volume_info(...) end },
  -- tethers (lua/tether.c): tethers.lua
  ["world:tether"] = { opts = { length = 1, compliance = 0 }, opts_arg = 4, nums = { "length", "compliance" },
                       call = function(f, o) local b = f.body.first return f.w:tether(b, b + 1, o) end },
  ["world:tether_info"] = { args = { 1 }, nums = { 1 }, call = function(f, ...)
                              if f.w:tether_count() == 0 then f.w:tether(f.body.first, f.body.first + 1) end
                              return f.w:tether_info(...) end },
  ["world:tether_count"] = { none = "a getter: no arguments" },
  ["world:load_tets"] = { opts = link{ mass = 1, radius = 0.02, volume_compliance = 0 }, opts_arg = 2,
                          nums = plus(link_nums, { "mass", "radius", "volume_compliance", "friction" }),
                          call = function(f, o) assert(f.w:save_tets("api_generic/tets", f.body))
                            return f.w:load_tets("api_generic/tets", o) end },
  ["world:save_tets"] = { none = "a path and a body" },
  ["world:volume_count"] = { none = "a getter: no arguments" },
  ["world:total_volume"] = { none = "a getter: no arguments" },
  -- Neo-Hookean tets (lua/volume.c, core/tet.c); young/poisson on lattice: neo_hookean.lua
  ["world:tet"] = { opts = { young = 1e5, poisson = 0.3 }, opts_arg = 5, nums = { "young", "poisson" },
                    call = function(f, o) local b = f.body.first
                      return f.w:tet(b, b + 1, b + 2, b + 4, o) end },
  ["world:tet_info"] = { args = { 1 }, nums = { 1 },
                         call = function(f, ...) local b = f.body.first
                           if f.w:tet_count() == 0 then f.w:tet(b, b + 1, b + 2, b + 4) end
                           return f.w:tet_info(...) end },
  ["world:tet_count"] = { none = "a getter: no arguments" },
}
for _, name in ipairs{ "angular_momentum", "bend_breaks", "bends", "bounds", "breaks", "closed", "colliders", "contacts", "damping", "distances", "dt",
                       "energy", "frame", "gravity", "hash", "iterations", "max_strain", "momentum", "particle_count",
                       "relaxation", "rigid_contacts", "rigids", "skins", "solver", "stats", "step", "substeps", "threads", "time", "tolerance",
                       "warnings" } do
  CASES["world:" .. name] = { none = "a getter or step: no arguments" }
end

-- ---- handles
CASES["collider:set_position"] = { args = { 0, 0, 0 }, nums = { 1, 2, 3 },
                                   call = function(f, ...) return f.col:set_position(...) end }
CASES["collider:set_velocity"] = { args = { 0, 0, 0 }, nums = { 1, 2, 3 },
                                   call = function(f, ...) return f.col:set_velocity(...) end }
CASES["collider:set_angular_velocity"] = { args = { 0, 0, 0 }, nums = { 1, 2, 3 },
                                           call = function(f, ...) return f.col:set_angular_velocity(...) end }
CASES["collider:set_rotation"] = { args = { 1, 0, 0, 0 }, nums = { 1, 2, 3, 4 },
                                   call = function(f, ...) return f.col:set_rotation(...) end }
CASES["collider:distance"] = { args = { 0, 0, 0 }, nums = { 1, 2, 3 },
                               call = function(f, ...) return f.col:distance(...) end }
for _, name in ipairs{ "material", "position", "remove", "rotation", "shape", "valid", "velocity", "world" } do
  CASES["collider:" .. name] = { none = "a getter or remove: no arguments" }
end
CASES["rigid:set_position"] = { args = { 0, 0, 0 }, nums = { 1, 2, 3 },
                                call = function(f, ...) return f.rb:set_position(...) end }
CASES["rigid:set_velocity"] = { args = { 0, 0, 0 }, nums = { 1, 2, 3 },
                                call = function(f, ...) return f.rb:set_velocity(...) end }
CASES["rigid:set_angular_velocity"] = { args = { 0, 0, 0 }, nums = { 1, 2, 3 },
                                        call = function(f, ...) return f.rb:set_angular_velocity(...) end }
CASES["rigid:distance"] = { args = { 0, 0, 0 }, nums = { 1, 2, 3 },
                            call = function(f, ...) return f.rb:distance(...) end }
CASES["rigid:set_rotation"] = { args = { 1, 0, 0, 0 }, nums = { 1, 2, 3, 4 },
                                call = function(f, ...) return f.rb:set_rotation(...) end }
CASES["rigid:apply_impulse"] = { args = { {1, 0, 0}, {0, 6.2, 0} }, nums = { 1, 2 },
                                 call = function(f, ...) return f.rb:apply_impulse(...) end }
for _, name in ipairs{ "angular_velocity", "mass", "position", "remove", "rotation", "shape", "valid", "velocity", "world" } do
  CASES["rigid:" .. name] = { none = "a getter or remove: no arguments" }
end
for _, name in ipairs{ "broken", "force", "length", "particles", "remove", "rest", "strain", "valid", "world" } do
  CASES["distance:" .. name] = { none = "a getter or remove: no arguments" }
end
for _, name in ipairs{ "angle", "broken", "force", "particles", "rest", "valid", "world" } do
  CASES["bend:" .. name] = { none = "a getter: no arguments" }
end
CASES["shape_match:rest"] = { args = { 1 }, nums = { 1 }, call = function(f, ...) return f.sm:rest(...) end }
for _, name in ipairs{ "particles", "stiffness", "strain", "world" } do
  CASES["shape_match:" .. name] = { none = "a getter: no arguments" }
end
CASES["pressure:set_pressure"] = { args = { 1.5 }, nums = { 1 }, call = function(f, ...) return f.pr:set_pressure(...) end }
for _, name in ipairs{ "pressure", "rest_volume", "volume", "world" } do
  CASES["pressure:" .. name] = { none = "a getter: no arguments" }
end
CASES["world:attach"] = { opts = { compliance = 0 }, opts_arg = 3, nums = { "compliance" },
                          call = function(f, o) return f.w:attach(f.r3, f.col, o) end }
-- a rigid body's grab: it takes every option (a particle's takes compliance only)
CASES["world:grab"] = { opts = { compliance = 0, at = {0, 0.1, 0} }, opts_arg = 3, nums = { "compliance", "at" },
                        call = function(f, o) return f.w:grab(f.rb, {0, 1, 0}, o) end }
CASES["world:attachments"] = { none = "a getter: no arguments" }
CASES["world:grabs"] = { none = "a getter: no arguments" }
for _, name in ipairs{ "force", "particle", "point", "remove", "valid" } do
  CASES["attach:" .. name] = { none = "a getter or remove: no arguments" }
end
CASES["grab:move"] = { args = { 0, 1, 0 }, nums = { 1, 2, 3 }, call = function(f, ...) return f.grab:move(...) end }
for _, name in ipairs{ "body", "force", "particle", "point", "release", "target", "valid" } do
  CASES["grab:" .. name] = { none = "a getter or release: no arguments" }
end
CASES["body:pin_where"] = { none = "a predicate function" }
CASES["body:pin_all"] = { none = "no arguments" }
CASES["body:unpin_all"] = { none = "no arguments" }
CASES["body:tether_to_pins"] = { opts = { compliance = 0 }, opts_arg = 2, nums = { "compliance" },
                                 call = function(f, o) return f.body:tether_to_pins(o) end }

-- ---- meshes and skins
CASES["mesh:transform"] = { opts = { scale = 2, translate = {0, 1, 0} }, nums = { "scale", "translate" },
                            call = function(f, o) return f.m:transform(o) end }
CASES["mesh:vertex"] = { args = { 1 }, nums = { 1 }, call = function(f, ...) return f.m:vertex(...) end }
CASES["mesh:normal"] = { args = { 1 }, nums = { 1 }, call = function(f, ...) return f.m:normal(...) end }
CASES["mesh:triangle"] = { args = { 1 }, nums = { 1 }, call = function(f, ...) return f.m:triangle(...) end }
for _, name in ipairs{ "bounds", "close", "copy", "triangle_count", "vertex_count" } do
  CASES["mesh:" .. name] = { none = "no arguments" }
end
CASES["mesh:save"] = { none = "a path" }
CASES["mesh:save_obj"] = { none = "a path" }
CASES["skin:vertex"] = { args = { 1 }, nums = { 1 }, call = function(f, ...) return f.skin:vertex(...) end }
CASES["skin:influences"] = { args = { 1 }, nums = { 1 }, call = function(f, ...) return f.skin:influences(...) end }
CASES["skin:bone_rotation"] = { args = { 1 }, nums = { 1 }, call = function(f, ...) return f.skin:bone_rotation(...) end }
CASES["skin:record_pc2"] = { opts = { rest = "obj", every = 1 }, opts_arg = 2, nums = { "every" },
                             call = function(f, o) return f.skin:record_pc2("api_generic/s.pc2", o) end }
for _, name in ipairs{ "bones", "bounds", "close", "closed", "mesh", "triangle_count", "update", "vertex_count", "world" } do
  CASES["skin:" .. name] = { none = "no arguments" }
end
CASES["skin:save"] = { none = "a path" }
CASES["skin:save_obj"] = { none = "a path" }

-- ---- renderer and recorders
CASES["renderer:camera"] = { opts = { eye = {3, 2, 3}, target = {0, 0, 0}, up = {0, 1, 0}, fov = 40 },
                             nums = { "eye", "target", "up", "fov" },
                             call = function(f, o) return f.r:camera(o) end }
CASES["renderer:draw"] = { opts = { strain_scale = 0.02, line_width = 1.5 }, opts_arg = 2,
                           nums = { "strain_scale", "line_width" },
                           call = function(f, o) return f.r:draw(f.w, o) end }
CASES["renderer:record"] = { opts = { fps = 30 }, opts_arg = 2, nums = { "fps" },
                             call = function(f, o) return f.r:record("api_generic/frames/", o) end }
CASES["renderer:pixel"] = { args = { 0, 0 }, nums = { 1, 2 }, call = function(f, ...) return f.r:pixel(...) end }
CASES["renderer:project"] = { args = { 0, 0, 0 }, nums = { 1, 2, 3 }, call = function(f, ...) return f.r:project(...) end }
for _, name in ipairs{ "close", "get_camera", "image", "info", "recording", "size", "stop", "strain_scale" } do
  CASES["renderer:" .. name] = { none = "no arguments" }
end
CASES["renderer:save_png"] = { none = "a path" }
for _, name in ipairs{ "close", "closed", "frames" } do
  CASES["recorder:" .. name] = { none = "no arguments" }
end

-- ---- the API as the metatables list it --------------------------------------------
local function methods_of(kind, obj, into)
  local mt = getmetatable(obj)
  local idx = type(mt) == "table" and mt.__index
  expect.eq(type(idx), "table", kind .. ": a method table under __index")
  for k, v in pairs(idx) do
    if type(v) == "function" then into[kind .. ":" .. k] = true end
  end
end

local function api()
  local f, names = fixture(), {}
  for k, v in pairs(wobble) do
    if type(v) == "function" then names["wobble." .. k] = true end
  end
  methods_of("world", f.w, names)
  methods_of("distance", f.c, names)
  methods_of("bend", f.bend, names)
  methods_of("collider", f.col, names)
  methods_of("rigid", f.rb, names)
  methods_of("shape_match", f.sm, names)
  methods_of("pressure", f.pr, names)
  methods_of("attach", f.att, names)
  methods_of("grab", f.grab, names)
  methods_of("body", f.body, names)
  methods_of("mesh", f.m, names)
  methods_of("skin", f.skin, names)
  methods_of("renderer", f.r, names)
  methods_of("recorder", f.rec, names)
  return names
end

test("every function of the API has a row in the table of cases, and every row a function", function()
  local names, missing, stale = api(), {}, {}
  for name in pairs(names) do
    if not CASES[name] then missing[#missing + 1] = name end
  end
  for name in pairs(CASES) do
    if not names[name] then stale[#stale + 1] = name end
  end
  table.sort(missing)
  table.sort(stale)
  expect.eq(table.concat(missing, " "), "", "functions without a row in api_generic.lua's CASES")
  expect.eq(table.concat(stale, " "), "", "rows of CASES naming no function")
  -- the walk found the API (a broken walk would find nothing missing)
  expect.truthy(names["world:distance"] and names["collider:set_velocity"] and names["wobble.world"])
end)

-- ---- the checks ----------------------------------------------------------------------
local function copy(t)
  local r = {}
  for k, v in pairs(t) do r[k] = type(v) == "table" and copy(v) or v end
  return r
end

-- fn on a fresh fixture must raise an error containing every pattern (plain), and
-- leave the world as it was
local function refused(name, f, fn, ...)
  local before = f.w:hash()
  local pats = { ... }
  local err = expect.error(fn, nil, name)
  local s = tostring(err)
  for _, p in ipairs(pats) do
    expect.truthy(s:find(p, 1, true), string.format("%s: error %q lacks %q", name, s, p))
  end
  expect.eq(f.w:hash(), before, name .. ": a refused call changes nothing")
end

-- every way to put a non-finite number into value v: itself, or one element of it
local function bad_variants(v)
  local out = {}
  if type(v) == "number" then
    for _, b in ipairs(BAD) do out[#out + 1] = { b, badname(b) } end
  elseif type(v) == "table" then
    for i = 1, #v do
      for _, b in ipairs(BAD) do
        local t = copy(v)
        t[i] = b
        out[#out + 1] = { t, badname(b) .. " at [" .. i .. "]" }
      end
    end
  end
  return out
end

local function method_name(name) return name:match("[:.]([%w_]+)") end

local function check_opts(name, case, base)
  local fname = method_name(name)
  -- an unknown key, named in the error
  local o = copy(base)
  o.no_such_key = 1
  local f = fixture()
  refused(name .. " {no_such_key}", f, function() return case.call(f, o) end,
          "to '" .. fname .. "'", "unknown key 'no_such_key'")
  -- every number in the options
  local nums = case.nums or {}
  for _, key in ipairs(nums) do
    local v = base[key]
    expect.truthy(v ~= nil, name .. ": the base options give " .. key)
    local variants = bad_variants(v)
    expect.gt(#variants, 0, name .. ": " .. key .. " holds numbers")
    for _, bv in ipairs(variants) do
      local oo = copy(base)
      oo[key] = bv[1]
      local ff = fixture()
      refused(name .. " {" .. key .. " = " .. bv[2] .. "}", ff, function() return case.call(ff, oo) end,
              "to '" .. fname .. "'", key)
    end
  end
end

test("options tables refuse an unknown key and non-finite numbers, changing nothing", function()
  local n = 0
  for name, case in pairs(CASES) do
    if case.opts then
      check_opts(name, case, case.opts)
      n = n + 1
    elseif case.shapes then
      for _, base in ipairs(case.shapes) do
        local nums = {}
        for k, v in pairs(base) do if k ~= "shape" and k ~= "mesh" then nums[#nums + 1] = k end end
        table.sort(nums)
        check_opts(name .. "/" .. base.shape, { call = case.call, nums = nums }, base)
        n = n + 1
      end
    end
  end
  expect.ge(n, 20, "option-taking functions checked")
end)

test("positional numbers refuse NaN and infinities, naming the argument, changing nothing", function()
  local n = 0
  for name, case in pairs(CASES) do
    if case.args then
      local fname = method_name(name)
      expect.truthy(case.nums and #case.nums > 0, name .. ": nums lists the number arguments")
      for _, pos in ipairs(case.nums) do
        for _, bv in ipairs(bad_variants(case.args[pos])) do
          local args = copy(case.args)
          args[pos] = bv[1]
          local f = fixture()
          refused(name .. " arg " .. pos .. " = " .. bv[2], f,
                  function() return case.call(f, table.unpack(args, 1, #case.args)) end,
                  "bad argument #" .. pos .. " to '" .. fname .. "'")
        end
      end
      n = n + 1
    end
  end
  expect.ge(n, 30, "functions with number arguments checked")
end)

test("the rows' valid calls work (so a refusal above is the bad value's doing)", function()
  for name, case in pairs(CASES) do
    if case.args and name ~= "wobble.read_frame" then
      local f = fixture()
      local ok, err = pcall(case.call, f, table.unpack(case.args, 1, #case.args))
      expect.truthy(ok, name .. " with its valid arguments: " .. tostring(err))
    elseif case.opts and name ~= "world:run" then
      local f = fixture()
      local ok, err = pcall(case.call, f, copy(case.opts))
      expect.truthy(ok, name .. " with its valid options: " .. tostring(err))
      if ok and name == "renderer:record" then f.r:stop() end
    elseif case.shapes then
      for _, base in ipairs(case.shapes) do
        local f = fixture()
        local ok, err = pcall(case.call, f, copy(base))
        expect.truthy(ok, name .. "/" .. base.shape .. " with its valid options: " .. tostring(err))
      end
    end
  end
end)
