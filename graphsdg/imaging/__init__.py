"""Image maths shared by the asset generator and the engine: environment maps and tonemapping. The asset generator
(assets/) and the engine (sim/, render/) both use its lat-long environment maps and tonemapping. Depends on nothing
else in graphsdg."""
