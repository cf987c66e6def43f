/* gltf_json.h: the glTF loader's view of the JSON document (C++, private to src/scene): Doc
 * reads it with the schema's types, each mistake an error naming the JSON path
 * ("materials[0].extensions.KHR_materials_sheen.sheenColorTexture.index: 7 does not exist"),
 * the same message for the same kind of mistake wherever it is. gltf_json.cpp checks the
 * document with it (check_document), gltf_material.cpp reads the materials. */
#ifndef GONIO_GLTF_JSON_H
#define GONIO_GLTF_JSON_H

#include "gltf_internal.h"

#include <cstdio>
#include <initializer_list>

namespace gltf {

const int MAX_DOC_ERRORS = 20; /* then only a count: a fuzzed file can have millions */

struct Doc {
    Ctx &c;
    const Json &root;
    bool glb;
    int errors = 0;
    std::vector<bool> unbounded; /* per accessor: a POSITION without min or max */
    size_t num_variants = 0;     /* KHR_materials_variants' variants */
    size_t num_unbounded = 0, first_unbounded = 0;

    Doc(Ctx &ctx, const Json &r, bool is_glb) : c(ctx), root(r), glb(is_glb) {}

    void error(const std::string &path, const char *fmt, ...) UTIL_PRINTF(3, 4)
    {
        c.failed = true;
        if (++errors > MAX_DOC_ERRORS)
            return;
        char msg[512];
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(msg, sizeof msg, fmt, ap);
        va_end(ap);
        util_error("%s: %s: %s", c.path, path.c_str(), msg);
    }

    static std::string show(const Json &v)
    {
        std::string s = v.dump(-1, ' ', false, Json::error_handler_t::replace);
        return s.size() > 40 ? s.substr(0, 37) + "..." : s;
    }
    static std::string at(const std::string &path, const char *key) { return path.empty() ? key : path + "." + key; }
    static std::string item(const std::string &path, size_t i) { return path + "[" + std::to_string(i) + "]"; }
    /* A key the file chose (attribute names), fit for a message: short, printable. */
    static std::string key_of(const std::string &k)
    {
        std::string s = k.substr(0, 64);
        for (char &ch : s)
            if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f)
                ch = '?';
        return s;
    }

    /* Member `key` of object o, nullptr when absent (an error when required). */
    const Json *member(const Json &o, const char *key, const std::string &path, bool required = false)
    {
        auto it = o.find(key);
        if (it != o.end())
            return &*it;
        if (required)
            error(at(path, key), "missing (required)");
        return nullptr;
    }
    const Json *typed(const Json &o, const char *key, const std::string &path, Json::value_t type, const char *what,
                      bool required = false)
    {
        const Json *v = member(o, key, path, required);
        if (v && v->type() != type) {
            error(at(path, key), "%s is not %s", show(*v).c_str(), what);
            return nullptr;
        }
        return v;
    }
    const Json *object(const Json &o, const char *key, const std::string &path, bool required = false)
    {
        return typed(o, key, path, Json::value_t::object, "an object", required);
    }
    const Json *array(const Json &o, const char *key, const std::string &path, bool required = false)
    {
        return typed(o, key, path, Json::value_t::array, "an array", required);
    }
    void boolean(const Json &o, const char *key, const std::string &path)
    {
        typed(o, key, path, Json::value_t::boolean, "true or false");
    }
    void string(const Json &o, const char *key, const std::string &path, bool required = false)
    {
        typed(o, key, path, Json::value_t::string, "a string", required);
    }
    bool is_number(const Json &v, const std::string &path)
    {
        if (v.is_number())
            return true;
        error(path, "%s is not a number", show(v).c_str());
        return false;
    }
    void number(const Json &o, const char *key, const std::string &path, bool required = false)
    {
        if (const Json *v = member(o, key, path, required))
            is_number(*v, at(path, key));
    }
    /* An array of numbers, n of them unless n is 0; true when it is one. */
    bool numbers(const Json &o, const char *key, const std::string &path, size_t n)
    {
        const Json *v = array(o, key, path);
        if (!v)
            return false;
        if (n && v->size() != n) {
            error(at(path, key), "must have %zu numbers (has %zu)", n, v->size());
            return false;
        }
        bool ok = true;
        for (size_t i = 0; i < v->size(); i++)
            ok &= is_number((*v)[i], item(at(path, key), i));
        return ok;
    }

    /* A non-negative integer in [lo, hi] (the validator's TYPE_MISMATCH, VALUE_NOT_IN_RANGE).
     * Returns it, or -1 when absent or bad. */
    int64_t integer(const Json &v, const std::string &path, uint64_t lo, uint64_t hi)
    {
        if (!v.is_number_integer()) {
            error(path, "%s is not an integer", show(v).c_str());
            return -1;
        }
        bool negative = !v.is_number_unsigned() && v.get<int64_t>() < 0;
        uint64_t u = negative ? 0 : v.get<uint64_t>();
        if (negative || u < lo || u > hi) {
            error(path, "%s is out of range (%llu..%llu)", show(v).c_str(), (unsigned long long)lo,
                  (unsigned long long)hi);
            return -1;
        }
        return int64_t(u);
    }
    int64_t integer(const Json &o, const char *key, const std::string &path, uint64_t lo, uint64_t hi,
                    bool required = false)
    {
        const Json *v = member(o, key, path, required);
        return v ? integer(*v, at(path, key), lo, hi) : -1;
    }

    /* An index into `n` objects of root array `kind` (the validator's TYPE_MISMATCH for 1.5 or
     * 1e20, UNRESOLVED_REFERENCE / INVALID_INDEX out of range). Returns it, or -1. */
    int64_t index(const Json &v, const std::string &path, const char *kind, size_t n)
    {
        if (!v.is_number_integer()) {
            error(path, "%s is not an integer index", show(v).c_str());
            return -1;
        }
        if (!v.is_number_unsigned() && v.get<int64_t>() < 0) {
            error(path, "%s is not a valid index (negative)", show(v).c_str());
            return -1;
        }
        if (v.get<uint64_t>() >= n) {
            if (n)
                error(path, "%s does not exist (%s has %zu entr%s)", show(v).c_str(), kind, n, n == 1 ? "y" : "ies");
            else
                error(path, "%s does not exist (the file has no %s)", show(v).c_str(), kind);
            return -1;
        }
        return int64_t(v.get<uint64_t>());
    }
    size_t count_of(const char *kind) const
    {
        auto it = root.find(kind);
        return it != root.end() && it->is_array() ? it->size() : 0;
    }
    int64_t index(const Json &o, const char *key, const std::string &path, const char *kind, bool required = false)
    {
        const Json *v = member(o, key, path, required);
        return v ? index(*v, at(path, key), kind, count_of(kind)) : -1;
    }
    void indices(const Json &o, const char *key, const std::string &path, const char *kind)
    {
        if (const Json *v = array(o, key, path))
            for (size_t i = 0; i < v->size(); i++)
                index((*v)[i], item(at(path, key), i), kind, count_of(kind));
    }

    void enum_int(const Json &o, const char *key, const std::string &path, std::initializer_list<int> values,
                  bool required = false)
    {
        const Json *v = member(o, key, path, required);
        if (!v)
            return;
        if (v->is_number_integer() && !(v->is_number_unsigned() && v->get<uint64_t>() > INT32_MAX))
            for (int x : values)
                if (v->get<int64_t>() == x)
                    return;
        std::string list;
        for (int x : values)
            list += (list.empty() ? "" : ", ") + std::to_string(x);
        error(at(path, key), "%s is not one of %s", show(*v).c_str(), list.c_str());
    }
    void enum_str(const Json &o, const char *key, const std::string &path, std::initializer_list<const char *> values,
                  bool required = false)
    {
        const Json *v = member(o, key, path, required);
        if (!v)
            return;
        if (v->is_string())
            for (const char *x : values)
                if (v->get_ref<const std::string &>() == x)
                    return;
        std::string list;
        for (const char *x : values)
            list += std::string(list.empty() ? "" : ", ") + x;
        error(at(path, key), "%s is not one of %s", show(*v).c_str(), list.c_str());
    }

    /* The objects of array o.key, each passed to f with its path and position. */
    template <class F> void each(const Json &o, const char *key, const std::string &path, F f)
    {
        const Json *a = array(o, key, path);
        if (!a)
            return;
        for (size_t i = 0; i < a->size(); i++) {
            std::string p = item(at(path, key), i);
            if (!(*a)[i].is_object())
                error(p, "%s is not an object", show((*a)[i]).c_str());
            else
                f((*a)[i], p, i);
        }
    }

    void check();
    void check_accessor(const Json &a, const std::string &p);
    void check_primitive(const Json &pr, const std::string &p);
    void check_node(const Json &n, const std::string &p);
};

/* ---- gltf_material.cpp: the materials, read and checked by the material table ------------- */
/* Readies c for the document's materials (root["materials"]: each read by material_read). */
void materials_read(Ctx &c, const Json &root);
/* Reads and checks material i at JSON path p into c's drafts (gltf_internal.h: MaterialDraft). */
void material_read(Doc &d, const Json &m, const std::string &p, size_t i);

} // namespace gltf

#endif
