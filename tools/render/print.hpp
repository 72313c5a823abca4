// The printed image on the sheet's top face (MODEL.md §6). A scene may give a PNG; without
// one the sheet carries a built-in poster: a coloured header with a title, a graphic block,
// and columns of text-like lines, so that a frame reads as printed matter at a glance and a
// tear through it is easy to follow. The image is stretched over the whole top face, its
// top row along the sheet's far edge (high y), and moves with the cells it was printed on.
#pragma once
#include "tools/render/image.hpp"
#include "tools/render/settings.hpp"

namespace papertear::render {

// The built-in poster, `size` x `size` pixels (a pure function of the size).
Image default_print(int size = 1024);

// The image a scene asks for: its PNG, or the built-in poster. Throws RenderError (naming
// print.image) when the PNG cannot be read.
Image load_print(const PrintSettings& print);

}  // namespace papertear::render
