/* draw.h: a small 8-bit RGBA raster canvas for plots and labelled images: anti-aliased lines
 * and circles, rectangles, a built-in 5x7 bitmap font, blits, a viridis colour map, PNG output.
 *
 * Colours are uint32_t 0xRRGGBBAA (sRGB, straight alpha). Coordinates: pixel (i, j) covers
 * [i, i+1) x [j, j+1), y down, so its centre is (i + 0.5, j + 0.5). Everything is clipped to
 * the canvas, and every drawing call except draw_clear and draw_blit blends source-over. */
#ifndef GONIO_DRAW_H
#define GONIO_DRAW_H

#include <stdbool.h>
#include <stdint.h>

typedef struct draw_canvas {
    int width, height;
    uint8_t *rgba; /* width * height * 4 bytes, rows top to bottom */
} draw_canvas;

/* Glyph cell of draw_text at scale 1: 5x7 glyphs advance by 6 pixels. */
#define DRAW_GLYPH_W 5
#define DRAW_GLYPH_H 7
#define DRAW_GLYPH_ADVANCE 6

/* A canvas of width x height (each >= 1), transparent black. */
void draw_create(draw_canvas *c, int width, int height);
void draw_destroy(draw_canvas *c); /* accepts a zeroed struct */
/* Sets every pixel to color (no blending). */
void draw_clear(draw_canvas *c, uint32_t color);
void draw_pixel(draw_canvas *c, int x, int y, uint32_t color);
/* A segment of the given width with round caps, anti-aliased by pixel coverage. */
void draw_line(draw_canvas *c, float x0, float y0, float x1, float y1, float thickness, uint32_t color);
/* One-pixel outline / filled rectangle covering pixels x..x+w-1, y..y+h-1. */
void draw_rect(draw_canvas *c, int x, int y, int w, int h, uint32_t color);
void draw_fill_rect(draw_canvas *c, int x, int y, int w, int h, uint32_t color);
/* Circle outline of radius r around (cx, cy), anti-aliased. */
void draw_circle(draw_canvas *c, float cx, float cy, float r, float thickness, uint32_t color);
/* One line of text whose top-left glyph corner is (x, y); each font pixel becomes a
 * scale x scale block. Characters outside printable ASCII 32..126 are drawn as '?'. The ink
 * lies inside draw_text_width(text, scale) x DRAW_GLYPH_H * scale. */
void draw_text(draw_canvas *c, int x, int y, int scale, uint32_t color, const char *text);
int draw_text_width(const char *text, int scale);
/* Copies a w x h RGBA image to (x, y), replacing the pixels (no blending). */
void draw_blit(draw_canvas *c, int x, int y, const uint8_t *rgba, int w, int h);
/* Heat-map colour for t in [0, 1] (clamped; NaN -> 0): matplotlib's viridis sampled at 17
 * evenly spaced stops, linearly interpolated (within 6/255 of the full 256-entry table). */
uint32_t draw_colormap(float t);
/* Writes the canvas as PNG (through image_write_png); false with an error on failure. */
bool draw_write_png(const draw_canvas *c, const char *path);

#endif
