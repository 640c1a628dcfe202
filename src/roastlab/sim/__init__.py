"""roastlab.sim"""
