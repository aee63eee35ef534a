-- json_logo_crush.lua: the reference thesis's multi-object scene (its Figure 16): a logo
-- of several soft pieces, read from a JSON particle config (assets/logo.json: six letters
-- of voxels, "WOBBLE", each its own part), crushed by a rigid box the script moves down,
-- holds, and lifts again. The letters squash, bulge sideways and spring back.
-- Run:     build/wobble run scripts/json_logo_crush.lua
-- Options: --set gap=0.2 (how close to the ground the press comes, m; deeper folds letters
--          for good: distance links alone do not resist a voxel turning inside out), --set seconds=4
--          --set export=1 (out/json_logo_crush.pvd: ParaView series with per-particle strain)
local args = wobble.args
local w = wobble.world{ substeps = 20, iterations = 2 }
local logo = assert(w:load_particles("../assets/logo.json")) -- relative to this file's folder
-- a thick slab (particles pushed into it come out below, never through the top), rough
-- enough to hold the letters' tops where it meets them
local press = w:collider{ shape = "box", center = {0, 1.1, 0}, half = {1.3, 0.2, 0.3}, friction = 0.8 }
local vtk = args.export and assert(w:record_vtk("json_logo_crush", { every = 2 }))

local function height(part)
  local lo, hi = math.huge, -math.huge
  for _, p in ipairs(part.particles) do
    local _, y = w:position(p)
    lo, hi = math.min(lo, y), math.max(hi, y)
  end
  return hi - lo
end

local rest, squashed = {}, {}
for i, part in ipairs(logo.parts) do rest[i], squashed[i] = height(part), math.huge end
local bottom = args.gap or 0.3 -- the lowest the press's bottom face comes
w:run{ seconds = args.seconds or 4, on_frame = function(w, f, t)
  -- down at 0.4 m/s, hold half a second, back up
  local down = (0.9 - bottom) / 0.4
  local y = t < down and 1.1 - 0.4 * t or (t < down + 0.5 and bottom + 0.2 or bottom + 0.2 + 0.4 * (t - down - 0.5))
  press:set_position(0, math.min(y, 1.1), 0)
  for i, part in ipairs(logo.parts) do squashed[i] = math.min(squashed[i], height(part)) end
end }
if vtk then vtk:close() end

print(string.format("logo: %d particles, %d links in %d parts", logo.count, logo.constraint_count, #logo.parts))
for i, part in ipairs(logo.parts) do
  print(string.format("  %-3s %2d particles: %.3f m tall, crushed to %3.0f%%, back to %3.0f%%", part.name, part.count,
                      rest[i], 100 * squashed[i] / rest[i], 100 * height(part) / rest[i]))
end
