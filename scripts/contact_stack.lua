-- contact_stack.lua: three soft blocks dropped onto each other come to rest as a stack
-- (particle-particle contacts): each block is a body of its own (its own
-- contact group), so they push instead of passing through. A particle's contact radius
-- is half its body's spacing by default; the renderer draws each block's hull out by that
-- radius, so the blocks are seen touching. Friction between the blocks keeps the stack from
-- sliding off the bumps of the particles; try --set friction=0, or --set contacts=0 to
-- watch them sink into each other.
-- Run: build/wobble run scripts/contact_stack.lua [--record out/stack.mp4]
local args = wobble.args
local w = wobble.world{ substeps = 20, iterations = 2, contacts = args.contacts ~= 0 }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.8 }
local mu = args.friction or 0.6
local blocks = {}
for i, b in ipairs{ { 0.35, 0.08, 3 }, { 0.28, 0.92, 1.5 }, { 0.2, 1.62, 1 } } do
  local h, y, mass = b[1], b[2], b[3]
  blocks[i] = w:lattice{ min = {-h + 0.03 * i, y, -h}, max = {h + 0.03 * i, y + 2 * h, h}, res = {6, 6, 6},
                         mass = mass, compliance = 2e-5, damping = 0.02, friction = mu }
end
-- the camera `--record` draws with and `wobble view` starts with
wobble.camera{ eye = {2.6, 1.8, 3.2}, target = {0, 0.95, 0} }
w:run{ seconds = args.seconds or 4 }
local function y_range(b)
  local lo, hi = math.huge, -math.huge
  for _, p in ipairs(b.particles) do
    local _, y = w:position(p)
    lo, hi = math.min(lo, y), math.max(hi, y)
  end
  return lo, hi
end
for i, b in ipairs(blocks) do
  local lo, hi = y_range(b)
  print(string.format("block %d (group %d): from y = %.3f to %.3f", i, b.group, lo, hi))
end
print(string.format("%d particle contacts in the last substep", w:stats().particle_contacts))

if test then  -- under `wobble test`: the header's claim
  test("three blocks dropped onto each other come to rest as a stack", function()
    for i = 2, 3 do
      local _, top = y_range(blocks[i - 1])
      local bottom = y_range(blocks[i])
      -- resting on the one below: their particles' contact spheres touch, the gap between
      -- the layers' centres r_below + r_above (measured 1.1 and 1.3 cm less: the contacts
      -- are pressed by the weight above); through each other it would be negative
      local touch = w:radius(blocks[i - 1].particles[1]) + w:radius(blocks[i].particles[1])
      expect.near(bottom - top, touch, 0.025, "block " .. i .. " rests on block " .. (i - 1))
    end
    local ke = w:energy()
    expect.lt(ke, 0.01, "at rest (kinetic energy, J)")
  end)
end
