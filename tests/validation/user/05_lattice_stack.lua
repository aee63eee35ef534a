-- Two lattice blocks stacked the obvious way: the upper block's bottom at the lower
-- block's top. With default radii (half the spacing) the two touching layers overlap by
-- 2r; physically the stack should stay a stack: the upper block pushed up by at most
-- that overlap, never thrown, nor slid off. Friction 0.5 on both blocks: docs/physics.md says
-- "Frictionless bodies never quite stop sliding on each other's particle bumps: give
-- stacked bodies some friction", so a user reading it does.
local S, RES = 0.4, 5                  -- 0.4 m cubes, spacing 0.1, r = 0.05
local r = S / (RES - 1) / 2

local function com(w, b)
  local sx, sy, sz = 0, 0, 0
  for _, p in ipairs(b.particles) do local x, y, z = w:position(p); sx, sy, sz = sx + x, sy + y, sz + z end
  local n = #b.particles
  return sx / n, sy / n, sz / n
end

local function stack(lower_y)
  local w = wobble.world{}
  w:collider{ shape = "plane", normal = { 0, 1, 0 }, offset = 0, friction = 0.5 }
  local lo = w:lattice{ min = { -S / 2, lower_y, -S / 2 }, max = { S / 2, lower_y + S, S / 2 }, res = { RES, RES, RES },
                        mass = 2, friction = 0.5 }
  local hi = w:lattice{ min = { -S / 2, lower_y + S, -S / 2 }, max = { S / 2, lower_y + 2 * S, S / 2 },
                        res = { RES, RES, RES }, mass = 1, friction = 0.5 }
  return w, lo, hi
end

local function check(lower_y, label)
  local w, lo, hi = stack(lower_y)
  local ux0, uy0, uz0 = com(w, hi)
  local _, ly0 = com(w, lo)
  local top, max_speed = uy0, 0
  w:run{ seconds = 4, on_frame = function(w)
    local _, y = com(w, hi)
    top = math.max(top, y)
    for i = 1, w:particle_count() do
      local vx, vy, vz = w:velocity(i)
      max_speed = math.max(max_speed, math.sqrt(vx * vx + vy * vy + vz * vz))
    end
  end }
  local ux, uy, uz = com(w, hi)
  local lx, ly, lz = com(w, lo)
  local ke = w:energy()
  print(string.format("%s: upper COM start %.3f, highest %.3f, end (%.3f, %.3f, %.3f); lower COM %.3f -> (%.3f, %.3f, "
    .. "%.3f); max particle speed %.2f m/s; kinetic %.2e J; warnings %d", label, uy0, top, ux, uy, uz, ly0, lx, ly, lz,
    max_speed, ke, (w:warnings())))
  -- the overlap 2r between the blocks (plus r into the ground when made at y = 0) is
  -- all that can lift the upper block: its COM rises by at most 3r + 1 cm
  expect.le(top, uy0 + 3 * r + 0.01, "upper block not thrown")
  expect.lt(max_speed, 1.0, "no particle flung")
  -- stays a stack: centred over the lower block within 2 cm, its COM at one block height
  -- plus one contact distance (2r) above the lower's, within 2 cm
  expect.lt(math.sqrt((ux - lx) ^ 2 + (uz - lz) ^ 2), 0.02, "upper block stays centred on the lower")
  expect.near(uy - ly, S + 2 * r, 0.02, "upper block rests on the lower, one contact distance above")
  expect.lt(ke, 1e-3, "the stack comes to rest")
end

test("two lattice blocks stacked the obvious way (lower from y = 0) stay stacked", function()
  check(0, "lower at y = 0")
end)

test("two lattice blocks stacked, the lower placed r above the ground (README placement)", function()
  check(r, "lower at y = r")
end)
