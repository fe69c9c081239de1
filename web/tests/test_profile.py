"""The browser runs on a temporary profile of its own, never the user's."""

import os
import pwd
import tempfile


def test_the_browser_profile_is_temporary(browser):
    context = browser.new_context()
    try:
        page = context.new_page()
        page.goto("chrome://version")
        profile = os.path.realpath(page.locator("#profile_path").inner_text().strip())
    finally:
        context.close()
    user_home = os.path.realpath(pwd.getpwuid(os.getuid()).pw_dir)
    assert profile.startswith(os.path.realpath(tempfile.gettempdir()) + os.sep), profile
    assert not profile.startswith(user_home + os.sep), profile
