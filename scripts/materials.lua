-- materials.lua: the material presets side by side (docs/physics.md, "Material presets"). Left to right:
-- blocks of rubber, jelly and foam dropped on the ground, each with the same 4 kg rigid
-- box dropped on it; sheets of cloth and leather dropped over a ball; a 10 mm steel cable
-- slung between two pins. Each body is built with `material = "name"` and nothing else
-- about its stuff: the preset gives its mass (density x volume), stiffness (Young's
-- modulus, Poisson's ratio), damping and friction. The renderer draws no text: the run
-- prints each body's figures in the same order.
-- Run: build/wobble run scripts/materials.lua [--record out/materials/]
local args = wobble.args
local w = wobble.world{ substeps = args.substeps or 20 }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.6 }

local S = 0.4 -- a block's side (m)
local rows = {}
for i, name in ipairs{ "rubber", "jelly", "foam" } do
  local x = -2.1 + (i - 1) * 0.8
  local b = w:lattice{ min = {x - S / 2, 0.1, -S / 2}, max = {x + S / 2, 0.1 + S / 2, S / 2}, res = {5, 3, 5},
                       material = name }
  local box = w:rigid{ shape = "box", half = {0.1, 0.04, 0.1}, mass = 4, pos = {x, 0.1 + S / 2 + 0.6, 0},
                       friction = 0.5 }
  rows[#rows + 1] = { name = name, body = b, box = box, vin = 0, vout = -math.huge }
end
for i, name in ipairs{ "cloth", "leather" } do
  local x = 0.35 + (i - 1) * 0.9
  w:collider{ shape = "sphere", center = {x, 0.25, 0}, radius = 0.25, friction = 0.3 }
  local b = w:cloth{ origin = {x - 0.35, 0.8, -0.35}, size = {0.7, 0.7}, res = {15, 15}, material = name }
  rows[#rows + 1] = { name = name, body = b }
end
local cable = w:rope{ from = {1.75, 0.7, 0}, to = {2.45, 0.7, 0}, segments = 16, material = "steel_cable" }
w:pin(cable.particles[1]); w:pin(cable.particles[#cable.particles])
rows[#rows + 1] = { name = "steel_cable", body = cable }

wobble.camera{ eye = {0.15, 1.7, 4.4}, target = {0.15, 0.35, 0} }

w:run{ seconds = args.seconds or 3, on_frame = function(w)
  for _, r in ipairs(rows) do
    if r.box then
      local _, vy = r.box:velocity()
      r.vin = math.min(r.vin, vy)
      if r.vin < -1 then r.vout = math.max(r.vout, vy) end
    end
  end
end }

local function mass(b)
  local m = 0
  for _, p in ipairs(b.particles) do m = m + w:mass(p) end
  return m
end
print("materials, left to right:")
for _, r in ipairs(rows) do
  local m = wobble.materials[r.name]
  local line = string.format("  %-11s E %8.3g Pa  nu %.2f  %6.0f kg/m^3  damping %8.3g Pa s  friction %.2f  body %.3g kg",
                             r.name, m.young, m.poisson, m.density, m.damping, m.friction, mass(r.body))
  if r.box then
    r.rebound = r.vout / -r.vin
    line = line .. string.format("  box rebound %.0f%% of %.1f m/s", 100 * r.rebound, -r.vin)
  end
  print(line)
end
local _, sag = w:position(cable.particles[9])
print(string.format("  the cable sags %.1f mm at its middle", (0.7 - sag) * 1000))

if test then  -- under `wobble test`: what the header says
  test("each body has its preset's mass and the boxes come to rest on the blocks", function()
    for _, r in ipairs(rows) do
      local m = wobble.materials[r.name]
      if r.box then
        expect.rel(mass(r.body), m.density * S * S * S / 2, 1e-9, r.name .. ": rho V")
        local _, y = r.box:position()
        expect.gt(y, 0.1 + S / 2 * 0.8, r.name .. ": the box rests on the block")
        expect.lt(r.rebound, 0.8, r.name .. ": rebound")
      end
    end
    expect.eq(w:stats().warnings, 0, "no numerical trouble")
  end)
end
