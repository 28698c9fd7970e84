/* vwalls/vwalls.h - the umbrella header of the vwalls library.
 *
 * What is not declared in these headers is not the API. The topic headers:
 * common.h (status, boxes), decomp.h (cells and walls), module.h (writing a module),
 * world.h (the runtime), engine.h (MPI set-up and agreement between processes),
 * scene.h, image.h and gen.h (reading and generating scenes, writing images),
 * outfile.h (writing any output file complete or not at all),
 * dynamic.h (moving objects between cells, collision and swept tests, the edit language),
 * balance.h (load balancing by walls, frames, cell shape, division) and map.h (cells
 * onto workers and processes).
 */
#ifndef VWALLS_VWALLS_H
#define VWALLS_VWALLS_H

#include "vwalls/common.h"
#include "vwalls/decomp.h"
#include "vwalls/module.h"
#include "vwalls/world.h"
#include "vwalls/engine.h"
#include "vwalls/scene.h"
#include "vwalls/image.h"
#include "vwalls/outfile.h"
#include "vwalls/gen.h"
#include "vwalls/dynamic.h"
#include "vwalls/balance.h"
#include "vwalls/map.h"

#endif
