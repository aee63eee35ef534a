-- the example of README.md's "Scene tests" section, kept running
test("a swinging rope never gets longer than it is", function()
  local w = wobble.world{ substeps = 20 }
  local rope = w:rope{ from = {0, 2, 0}, to = {1, 2, 0}, segments = 10 }
  w:pin(rope.particles[1])
  w:run{ seconds = 2, on_frame = function(w)
    local x, y, z = w:position(rope.particles[11])
    local reach = math.sqrt(x * x + (y - 2) ^ 2 + z * z)
    expect.le(reach, 1 + 1e-3, "free end within one rope length of the pin")
  end }
end)
