-- An elastic lattice block pressed to 60% of its height by a kinematic box, which is
-- then taken away at once. The block springs up (its stored elastic energy: physical),
-- but everything is symmetric about the vertical axis through its centre -- block, press,
-- ground -- so its centre of mass must rise straight up: no sideways drift, no spin.
-- Block placed r above the ground (README placement); links compliance 1e-3 (a springy
-- block; the default rigid links cannot be pressed at all).
-- RES 6 (no particle on the mirror planes) and 5 (a column on each: the links meeting
-- there are projected together, docs/physics.md "Solvers"; before that the block drifted 0.11 m)
local S = 0.4
local SPEED, TARGET = 0.1, 0.6

local function com(w, b)
  local sx, sy, sz = 0, 0, 0
  for _, p in ipairs(b.particles) do local x, y, z = w:position(p); sx, sy, sz = sx + x, sy + y, sz + z end
  local n = #b.particles
  return sx / n, sy / n, sz / n
end

for _, RES in ipairs{ 6, 5 } do
test(RES .. " particles across: a symmetric elastic block released from a press springs straight up", function()
  local r = S / (RES - 1) / 2
  local w = wobble.world{}
  w:collider{ shape = "plane", normal = { 0, 1, 0 }, offset = 0, friction = 0.5 }
  local b = w:lattice{ min = { -S / 2, r, -S / 2 }, max = { S / 2, r + S, S / 2 }, res = { RES, RES, RES }, mass = 2,
                       compliance = 1e-3 }
  local half = 0.1
  local face0 = r + S + r + 0.02
  local face_low = r + TARGET * S + r
  local t_down = (face0 - face_low) / SPEED
  local t_release = t_down + 1.0
  local press = w:collider{ shape = "box", center = { 0, face0 + half, 0 }, half = { 0.6, half, 0.6 }, friction = 0.5 }
  local x0, _, z0 = com(w, b)
  local drift, top, min_h = 0, -math.huge, math.huge
  local g, M = 9.81, 2
  local stored, y_rel = nil, nil
  w:run{ seconds = t_release + 2, on_frame = function(w, f, t)
    local face = t < t_down and face0 - SPEED * t or (t < t_release and face_low or 5)
    press:set_position(0, face + half, 0)
    local x, y, z = com(w, b)
    drift = math.max(drift, math.sqrt((x - x0) ^ 2 + (z - z0) ^ 2))
    if t > t_release then top = math.max(top, y) end
    if not stored and t >= t_release - 1e-9 then
      -- the elastic energy at release: the potential less the weight's M g y_com
      local ke, pe = w:energy()
      stored, y_rel = pe - M * g * y + ke, y
    end
    local _, miny, _, _, maxy = w:bounds()
    min_h = math.min(min_h, maxy - miny)
  end }
  local lx, ly, lz = w:angular_momentum()
  print(string.format("pressed to %.3f of its height; after release COM up to %.3f m; max sideways drift of the COM "
    .. "%.4f m; angular momentum at the end (%.2e, %.2e, %.2e); warnings %d", min_h / S, top, drift, lx, ly, lz,
    (w:warnings())))
  expect.lt(min_h / S, TARGET + 0.05, "pressed to about 60%")
  -- energy: the COM can rise at most by the elastic (and kinetic) energy stored at release
  -- over M g (all of it turned into lift; in fact much stays in vibration)
  print(string.format("stored at release %.3f J: the COM may rise %.3f m at most; it rose %.3f m", stored,
    stored / (M * g), top - y_rel))
  expect.le(top - y_rel, stored / (M * g) + 0.005, "rise bounded by the stored energy")
  -- by symmetry the sideways drift is round-off; 1 cm allowed for the solver's
  -- order-dependent (Gauss-Seidel) asymmetry
  expect.lt(drift, 0.01, "COM rises straight up")

end)
end
