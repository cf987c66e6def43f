/* gltf_files.cpp: the file access of the glTF loader. tinygltf's own callbacks expand `~` and
 * `$VAR` (wordexp), read any path and fall back to the working directory; these read only
 * regular files under the scene's folder (after `..`, percent-decoding and symlinks: tinygltf
 * decodes URIs before it joins them), unless scene_allow_outside_files. A refused file is an
 * error naming it that says nothing of whether it exists or how large it is. */
#include "gltf_internal.h"

#include <cstdlib>
#include <sys/stat.h>
#include <unistd.h>

namespace gltf {

/* The absolute, lexically normalised form of p ("." and ".." resolved, no symlinks). */
std::string normal_path(const std::string &p)
{
    std::string full = p;
    if (p.empty() || p[0] != '/') {
        char cwd[4096];
        if (!getcwd(cwd, sizeof cwd))
            return std::string();
        full = std::string(cwd) + "/" + p;
    }
    std::vector<std::string> parts;
    size_t i = 0;
    while (i <= full.size()) {
        size_t j = full.find('/', i);
        if (j == std::string::npos)
            j = full.size();
        std::string part = full.substr(i, j - i);
        if (part == "..") {
            if (!parts.empty())
                parts.pop_back();
        } else if (!part.empty() && part != ".") {
            parts.push_back(part);
        }
        i = j + 1;
    }
    std::string out;
    for (const auto &part : parts)
        out += "/" + part;
    return out.empty() ? "/" : out;
}

bool under(const std::string &path, const std::string &folder)
{
    return folder == "/" || (path.size() > folder.size() && path.compare(0, folder.size(), folder) == 0 &&
                             path[folder.size()] == '/');
}

bool fs_file_exists(const std::string &path, void *user)
{
    Ctx &c = *static_cast<Ctx *>(user);
    struct stat st;
    /* tinygltf tries the scene's folder, then the working directory: never the latter (with
     * a scene in the working directory both are its folder). */
    bool first = c.base_dir.empty() || path.compare(0, c.base_dir.size(), c.base_dir) == 0;
    if (!first && !allow_outside_files)
        return false;
    /* Lexically against the folder as named (a symlinked folder is the scene's folder), then
     * resolved against the folder resolved. */
    const std::string lexical = normal_path(path), folder = normal_path(c.base_dir.empty() ? "." : c.base_dir);
    if (lexical == folder) {
        c.access_errors.push_back("'" + path + "' is not a regular file");
        return false;
    }
    if (!allow_outside_files && !under(lexical, folder)) {
        c.access_errors.push_back("'" + path + "' is outside the scene's folder (--allow-outside-files reads it)");
        return false;
    }
    char *real = realpath(path.c_str(), nullptr);
    if (!real)
        return false;
    std::string resolved(real);
    free(real);
    if (!allow_outside_files && !under(resolved, c.folder)) {
        c.access_errors.push_back("'" + path + "' links outside the scene's folder (--allow-outside-files reads it)");
        return false;
    }
    if (stat(resolved.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) {
        c.access_errors.push_back("'" + path + "' is not a regular file");
        return false;
    }
    return true;
}

std::string fs_expand(const std::string &path, void *) { return path; }

bool fs_read(std::vector<unsigned char> *out, std::string *err, const std::string &path, void *)
{
    size_t size = 0;
    void *data = util_read_file(path.c_str(), &size);
    if (!data) {
        if (err)
            *err += "cannot read " + path;
        return false;
    }
    out->assign(static_cast<unsigned char *>(data), static_cast<unsigned char *>(data) + size);
    free(data);
    return true;
}

bool fs_write(std::string *err, const std::string &, const std::vector<unsigned char> &, void *)
{
    if (err)
        *err += "the loader writes no files";
    return false;
}

} // namespace gltf
