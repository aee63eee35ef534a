-- Restitution: a particle dropped from height h onto a plane with restitution e bounces
-- back to e^2 h (the normal speed is reversed and scaled by e at the bounce).
local g = 9.81

local function bounce(e, h0)
  local w = wobble.world{}
  w:collider{ shape = "plane", normal = { 0, 1, 0 }, offset = 0, restitution = e }
  local rad = 0.02
  local p = w:particle{ pos = { 0, rad + h0, 0 } }
  local falling, apex, bounced = true, -math.huge, false
  w:run{ seconds = 2.5, on_frame = function(w)
    local _, y = w:position(p)
    local _, vy = w:velocity(p)
    if falling and vy > 0 then falling, bounced = false, true end
    if bounced then
      apex = math.max(apex, y - rad)
      if vy < 0 and y - rad < apex - 1e-3 then return false end   -- past the first apex
    end
  end }
  return apex
end

for _, e in ipairs{ 0.5, 0.8 } do
  test(string.format("a particle dropped 1 m on a plane of restitution %.1f bounces to e^2 h", e), function()
    local apex = bounce(e, 1.0)
    print(string.format("e = %.1f: apex %.4f m, expected %.4f m", e, apex, e * e))
    -- the apex is sampled per frame (1/60 s: near the top the height changes by at most
    -- g dt^2 / 8 = 0.34 mm) and the impact falls within a substep (the speed at impact is
    -- off by up to g h = 1.6 cm/s of 4.4 m/s): 3%
    expect.rel(apex, e * e, 0.03, "bounce apex")
  end)
end
