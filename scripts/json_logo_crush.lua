-- json_logo_crush.lua: the reference thesis's multi-object scene (its Figure 16): a logo
-- of several soft pieces, read from a JSON particle config (assets/logo.json: six letters
-- of voxels, "WOBBLE", each its own part), crushed by a rigid box the script moves down,
-- holds, and lifts again. The letters squash, bulge sideways into their neighbours and
-- push them (particle-particle contacts: each letter is a contact group of its
-- own) instead of flowing into them as in the thesis, then spring back. The file's
-- particles have a radius of 10 mm, made for drawing; here they get half the voxel
-- size (35 of 80 mm), so a particle can neither reach another letter's particles nor
-- slip between them. Try --set contacts=0 to watch the letters run into each other.
-- Run:     build/wobble run scripts/json_logo_crush.lua
--          build/wobble test scripts/json_logo_crush.lua   (runs it and checks the letters)
-- Options: --set gap=0.25 (how close to the ground the press comes, m, default 0.35; deeper folds letters
--          for good: distance links alone do not resist a voxel turning inside out), --set seconds=4
--          --set export=1 (out/json_logo_crush.pvd: ParaView series with per-particle strain)
--          --set contacts=0 (no contacts between the letters)
local args = wobble.args
local w = wobble.world{ substeps = 20, iterations = 2, contacts = args.contacts ~= 0 }
-- relative to this file's folder; some friction between the letters where they touch, and
-- each letter collides with itself too, so a letter pushed hard by its neighbour cannot
-- turn a voxel inside out and stay tangled
local logo = assert(w:load_particles("../assets/logo.json", { radius = 0.035, friction = 0.3, self_collide = true }))
-- the file puts the letters' lowest particles 11 mm up, their old radius: lift them to
-- rest on the ground with the new one (no jolt from the ground plane at the start)
local lowest = math.huge
for _, p in ipairs(logo.particles) do lowest = math.min(lowest, select(2, w:position(p))) end
for _, p in ipairs(logo.particles) do
  local x, y, z = w:position(p)
  w:set_position(p, x, y - lowest + 0.035, z)
end
-- a thick slab (particles pushed into it come out below, never through the top), rough
-- enough to hold the letters' tops where it meets them
-- the links' lengths as built: each letter's worst strain at the end says whether it
-- came back whole
local links, rest_len = w:distances(), {}
local function length(c)
  local a, b = c:particles()
  local ax, ay, az = w:position(a)
  local bx, by, bz = w:position(b)
  return math.sqrt((ax - bx) ^ 2 + (ay - by) ^ 2 + (az - bz) ^ 2)
end
for k, c in ipairs(links) do rest_len[k] = length(c) end
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
local bottom = args.gap or 0.35
local touched = 0 -- the most contacts between two letters' particles in a frame -- the lowest the press's bottom face comes
w:run{ seconds = args.seconds or 4, on_frame = function(w, f, t)
  -- down at 0.4 m/s, hold half a second, back up
  local down = (0.9 - bottom) / 0.4
  local y = t < down and 1.1 - 0.4 * t or (t < down + 0.5 and bottom + 0.2 or bottom + 0.2 + 0.4 * (t - down - 0.5))
  press:set_position(0, math.min(y, 1.1), 0)
  for i, part in ipairs(logo.parts) do squashed[i] = math.min(squashed[i], height(part)) end
  local between = 0
  for _, c in ipairs(w:contacts()) do
    if w:group(c.a) ~= w:group(c.b) then between = between + 1 end
  end
  touched = math.max(touched, between)
end }
if vtk then vtk:close() end

print(string.format("logo: %d particles, %d links in %d parts", logo.count, logo.constraint_count, #logo.parts))
for i, part in ipairs(logo.parts) do
  print(string.format("  %-3s %2d particles: %.3f m tall, crushed to %3.0f%%, back to %3.0f%%", part.name, part.count,
                      rest[i], 100 * squashed[i] / rest[i], 100 * height(part) / rest[i]))
end

-- the closest two particles of different letters, over their contact distance r_i + r_j
-- (the file's letters start one voxel, 80 mm, apart: 1.14)
local closest = math.huge
for i, a in ipairs(logo.parts) do
  for j = i + 1, #logo.parts do
    for _, p in ipairs(a.particles) do
      local px, py, pz = w:position(p)
      for _, q in ipairs(logo.parts[j].particles) do
        local qx, qy, qz = w:position(q)
        closest = math.min(closest, math.sqrt((px - qx) ^ 2 + (py - qy) ^ 2 + (pz - qz) ^ 2) / (w:radius(p) + w:radius(q)))
      end
    end
  end
end
local strain = {}
for k, c in ipairs(links) do
  local g = w:group((c:particles()))
  strain[g] = math.max(strain[g] or 0, math.abs(length(c) / rest_len[k] - 1))
end
print(string.format("closest particles of two letters: %.3f of their contact distance; at most %d contacts " ..
                    "between letters in a frame", closest, touched))

if test then  -- under `wobble test`: the header's claim
  test("the crushed letters push each other instead of merging, and spring back", function()
    expect.gt(touched, 0, "the letters bulged into each other")
    -- the press and the links move particles after the contact pass of a substep; 10%
    -- of the contact distance covers that (as in tests/validation/contacts.lua)
    expect.ge(closest, 0.9, "no particle of one letter within 0.9 x contact distance of another's")
    for i, part in ipairs(logo.parts) do
      expect.lt(squashed[i] / rest[i], 0.8, part.name .. " was crushed")
      expect.gt(height(part) / rest[i], 0.95, part.name .. " sprang back")
      -- measured below 1.2%; a voxel turned inside out stretches a link by 30% or more
      expect.lt(strain[part.group], 0.05, part.name .. " came back whole: every link within 5% of its length")
    end
  end)
end
