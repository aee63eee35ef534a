-- rigid_pile.lua: a pile of 64 bodies poured into a bin: the substep's broad
-- phase (body pairs by a sort and sweep on swept boxes, colliders culled by bounding
-- spheres, rigid.c) must leave out no pair that touches. After 4 s no two bodies overlap
-- by more than 2 mm and every body is inside the bin.
--
-- Tolerance: resting contacts sink by about g h^2 per substep per body below (2.7e-5 m at
-- h = 1/600 s: a stack of 5 sinks 1.9e-4 m at the top, rigid_stack.lua); the pile is 3 to
-- 4 bodies deep and pressed sideways too: 2 mm, 1 % of a body's size (measured: 1.7e-4 m).
-- Missed pairs (boxes of the sweep too small) threw bodies out of the bin.

local g = 9.81

-- q (w, x, y, z) applied to v
local function rotate(qw, qx, qy, qz, vx, vy, vz)
  local tx = 2 * (qy * vz - qz * vy)
  local ty = 2 * (qz * vx - qx * vz)
  local tz = 2 * (qx * vy - qy * vx)
  return vx + qw * tx + (qy * tz - qz * ty), vy + qw * ty + (qz * tx - qx * tz), vz + qw * tz + (qx * ty - qy * tx)
end

test("64 boxes and spheres poured into a bin: no two overlap, none leaves the bin", function()
  local w = wobble.world{ gravity = {0, -g, 0}, substeps = 10 }
  local W = 0.6 -- the bin's inner half width
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.4 }
  for _, s in ipairs{ {1, 0}, {-1, 0}, {0, 1}, {0, -1} } do
    w:collider{ shape = "box", center = {s[1] * (W + 0.1), 0.6, s[2] * (W + 0.1)},
                half = {s[1] ~= 0 and 0.1 or W + 0.2, 0.6, s[2] ~= 0 and 0.1 or W + 0.2}, friction = 0.4 }
  end
  local bodies, half, R = {}, 0.1, 0.1
  local k = 0
  for layer = 0, 3 do
    for i = 0, 3 do
      for j = 0, 3 do
        k = k + 1
        local pos = {-0.45 + 0.3 * i + 0.02 * (layer % 2), 0.3 + 0.3 * layer, -0.45 + 0.3 * j + 0.03 * (k % 3)}
        if k % 4 == 0 then
          bodies[#bodies + 1] = { kind = "sphere", rb = w:rigid{ shape = "sphere", radius = R, pos = pos, friction = 0.4 } }
        else
          local a = 0.3 * k
          bodies[#bodies + 1] = { kind = "box", rb = w:rigid{ shape = "box", half = {half, half, half}, pos = pos, friction = 0.4,
                                                              rotation = {math.cos(a), math.sin(a) * 0.6, math.sin(a) * 0.8, 0} } }
        end
      end
    end
  end
  w:run{ seconds = 4 }
  -- the deepest point of one body inside another: sphere centres against each other,
  -- box corners and sphere centres against boxes (rb:distance, negative inside)
  local worst, where = 0, ""
  local function points(b)
    local x, y, z = b.rb:position()
    if b.kind == "sphere" then return { {x, y, z} }, R end
    local qw, qx, qy, qz = b.rb:rotation()
    local pts = {}
    for _, sx in ipairs{-1, 1} do for _, sy in ipairs{-1, 1} do for _, sz in ipairs{-1, 1} do
      local cx, cy, cz = rotate(qw, qx, qy, qz, sx * half, sy * half, sz * half)
      pts[#pts + 1] = {x + cx, y + cy, z + cz}
    end end end
    return pts, 0
  end
  for a = 1, #bodies do
    local pa, ra = points(bodies[a])
    for _, p in ipairs(pa) do
      -- ra: a sphere's radius (its one point is its centre), 0 for a box's corners
      expect.lt(math.abs(p[1]) + ra, W + 1e-3, "inside the bin (x)")
      expect.lt(math.abs(p[3]) + ra, W + 1e-3, "inside the bin (z)")
      expect.gt(p[2] - ra, -1e-3, "above the ground")
    end
    for b = 1, #bodies do
      if a ~= b and (bodies[b].kind == "box" or bodies[a].kind == "sphere") then
        for _, p in ipairs(pa) do
          local d
          if bodies[b].kind == "box" then
            d = bodies[b].rb:distance(p[1], p[2], p[3]) - ra
          else
            local x, y, z = bodies[b].rb:position()
            d = math.sqrt((p[1] - x) ^ 2 + (p[2] - y) ^ 2 + (p[3] - z) ^ 2) - ra - R
          end
          if d < worst then worst, where = d, a .. " in " .. b end
        end
      end
    end
  end
  expect.gt(worst, -2e-3, "deepest overlap between two bodies (" .. where .. ")")
end)
