"""Image maths that both the asset generator (assets/) and the engine (sim/, render/) use: lat-long
environment maps and tonemapping. Depends on nothing else in graphsdg."""
