-- wobble.bench: what the benchmark scenes (tests/bench/*.lua) share.
local M = {}

-- one JSON object per scene for `wobble bench --json`: keys sorted, so runs diff cleanly
function M.json(r)
  local keys = {}
  for k in pairs(r) do keys[#keys + 1] = k end
  table.sort(keys)
  local parts = {}
  for _, k in ipairs(keys) do
    local v = r[k]
    parts[#parts + 1] = string.format("%q: %s", k, type(v) == "string" and string.format("%q", v)
      or (math.type(v) == "integer" and tostring(v) or string.format("%.6g", v)))
  end
  return "{" .. table.concat(parts, ", ") .. "}"
end

return M
